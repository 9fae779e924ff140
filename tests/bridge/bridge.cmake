# caracara-bridge with the Foxglove reference client and the MCAP reference reader (npm packages
# pinned in tests/bridge/package-lock.json, cached under /var/cache/caracara-npm), through a
# real ssh -L forward to a private sshd (tests/bridge/test_bridge.py).
add_test(NAME e2e_bridge
         COMMAND /usr/bin/python3 -m unittest -v test_bridge
         WORKING_DIRECTORY ${CMAKE_CURRENT_LIST_DIR})
set_tests_properties(e2e_bridge PROPERTIES
                     ENVIRONMENT "CARACARA_BUILD_DIR=${CMAKE_BINARY_DIR};PYTHONDONTWRITEBYTECODE=1;${CARACARA_TEST_ENV}"
                     TIMEOUT 600
                     LABELS "e2e;bridge")

# The cockpit in Debian's chromium (headless, puppeteer-core) through the same kind of forward.
add_test(NAME e2e_cockpit
         COMMAND /usr/bin/python3 -m unittest -v test_cockpit
         WORKING_DIRECTORY ${CMAKE_CURRENT_LIST_DIR})
set_tests_properties(e2e_cockpit PROPERTIES
                     ENVIRONMENT "CARACARA_BUILD_DIR=${CMAKE_BINARY_DIR};PYTHONDONTWRITEBYTECODE=1;${CARACARA_TEST_ENV}"
                     TIMEOUT 600
                     LABELS "e2e;bridge;cockpit")
