# caracara-bridge with the Foxglove reference client and the MCAP reference reader (npm packages
# pinned in tests/bridge/package-lock.json, cached under /var/cache/caracara-npm), through a
# real ssh -L forward to a private sshd (tests/bridge/test_bridge.py).
# The packages are installed by the setup test npm_bridge (tests/npm_packages.py: npm ci from the
# lock file, outside any namespace) before either test below starts; the tests only check them.
# Labelled as its users: CTest adds it to any run that selects one of them (-R, -L), and a run
# that leaves them out by label (-LE bridge) leaves it out too.
add_test(NAME npm_bridge COMMAND /usr/bin/python3 ${CMAKE_SOURCE_DIR}/tests/npm_packages.py ${CMAKE_CURRENT_LIST_DIR})
set_tests_properties(npm_bridge PROPERTIES FIXTURES_SETUP npm_bridge LABELS "e2e;bridge" TIMEOUT 600
                     SKIP_RETURN_CODE 77)
caracara_python_test(e2e_bridge test_bridge ${CMAKE_CURRENT_LIST_DIR} LABELS e2e bridge)
set_tests_properties(e2e_bridge PROPERTIES FIXTURES_REQUIRED npm_bridge)

# The cockpit in Debian's chromium (headless, puppeteer-core) through the same kind of forward.
caracara_python_test(e2e_cockpit test_cockpit ${CMAKE_CURRENT_LIST_DIR} LABELS e2e bridge cockpit)
set_tests_properties(e2e_cockpit PROPERTIES FIXTURES_REQUIRED npm_bridge)
