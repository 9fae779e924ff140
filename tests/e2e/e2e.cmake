# End-to-end tests (Python, python3-dbus): a private dbus-daemon, caracara-sim and caracarad per
# test class, driven like a user would (python3-dbus, busctl, caracaractl, the example mission).
# Included from tests/CMakeLists.txt. Needs Debian's /usr/bin/python3 with python3-dbus and
# python3-gi, busctl and dbus-daemon; run with `ctest -L e2e`.
set(CARACARA_E2E_DIR ${CMAKE_CURRENT_LIST_DIR})
foreach(name vehicle introspection caracaractl mission paths_out faults)
  add_test(NAME e2e_${name}
           COMMAND /usr/bin/python3 -m unittest -v test_${name}
           WORKING_DIRECTORY ${CARACARA_E2E_DIR})
  set_tests_properties(e2e_${name} PROPERTIES
                       ENVIRONMENT "CARACARA_BUILD_DIR=${CMAKE_BINARY_DIR};PYTHONDONTWRITEBYTECODE=1"
                       TIMEOUT 600
                       LABELS e2e)
endforeach()
