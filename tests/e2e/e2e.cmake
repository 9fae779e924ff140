# End-to-end tests (Python, python3-dbus): a private dbus-daemon, caracara-sim and caracarad per
# test class, driven like a user would (python3-dbus, busctl, caracaractl, the example mission).
# Included from tests/CMakeLists.txt. Needs Debian's /usr/bin/python3 with python3-dbus and
# python3-gi, busctl and dbus-daemon; run with `ctest -L e2e`.
set(CARACARA_E2E_DIR ${CMAKE_CURRENT_LIST_DIR})
# org.caracara.Vehicle1, one file per interface or behaviour (test_<name>.py).
foreach(name properties announcements thrusters bus_recovery budget motion packet kill_and_arming power_off
             command_timeout client_loss pilot_lost start_and_sigterm invalid_input teensy
             introspection caracaractl mission faults gpio_lines dive_crash failsafes
             packet_kill fault_reports wheels bus_lost vanished_lines adapter_limits start_killed
             command_timeout_timer thrust_profiles zero_thrusters_step realtime teensy_silence motor_test
             direction_detection bus_scan)
  add_test(NAME e2e_${name}
           COMMAND /usr/bin/python3 -m unittest -v test_${name}
           WORKING_DIRECTORY ${CARACARA_E2E_DIR})
  set_tests_properties(e2e_${name} PROPERTIES
                       ENVIRONMENT "CARACARA_BUILD_DIR=${CMAKE_BINARY_DIR};PYTHONDONTWRITEBYTECODE=1;${CARACARA_TEST_ENV}"
                       TIMEOUT 600
                       LABELS e2e)
endforeach()
# Seven direction detections of eight pulses each, every pulse after the vehicle settles.
set_tests_properties(e2e_direction_detection PROPERTIES TIMEOUT 1200)

# The dive recorder: a dive listed and plotted, bad dive files refused, and the regression dives
# of tests/dives replayed against their expected output (tests/dives/test_dives.py).
add_test(NAME e2e_dives
         COMMAND /usr/bin/python3 -m unittest -v test_dives
         WORKING_DIRECTORY ${CMAKE_CURRENT_LIST_DIR}/../dives)
set_tests_properties(e2e_dives PROPERTIES
                     ENVIRONMENT "CARACARA_BUILD_DIR=${CMAKE_BINARY_DIR};PYTHONDONTWRITEBYTECODE=1;${CARACARA_TEST_ENV}"
                     TIMEOUT 600
                     LABELS e2e)
