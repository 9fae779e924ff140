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
             preflight bus_scan frames)
  caracara_python_test(e2e_${name} test_${name} ${CARACARA_E2E_DIR})
endforeach()
# Direction detection, one CTest test per vehicle (test class), so the three rigs run side by
# side: each detection is eight pulses, every pulse after the vehicle settles (about 30 s).
foreach(case reversed:ReversedThrustersTest fragment:WrittenFragmentTest disconnected:DisconnectedThrusterTest)
  string(REPLACE ":" ";" case "${case}")
  list(GET case 0 short)
  list(GET case 1 class)
  caracara_python_test(e2e_direction_detection_${short} test_direction_detection.${class} ${CARACARA_E2E_DIR}
                       TIMEOUT 900)
endforeach()

# The dive recorder: a dive listed and plotted, bad dive files refused, and the regression dives
# of tests/dives replayed against their expected output (tests/dives/test_dives.py); motor tests
# and a direction detection run in the dive at the wire's times, and the detection's plot
# (tests/dives/test_commissioning_dive.py).
foreach(name dives commissioning_dive)
  caracara_python_test(e2e_${name} test_${name} ${CMAKE_CURRENT_LIST_DIR}/../dives)
endforeach()
