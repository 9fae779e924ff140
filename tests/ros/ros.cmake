# caracara-ros against a second DDS vendor (tests/ros/test_ros.py): a Fast DDS peer whose types
# fastddsgen makes from the published ROS 2 message definitions (npm, pinned in
# tests/ros/package-lock.json), in a private network namespace (unshare --net: loopback and
# multicast only, no packet leaves the machine). ctest -L ros.
# Its packages are installed by the setup test npm_ros (tests/npm_packages.py: npm ci from the lock
# file) outside the namespace, before e2e_ros isolates; inside, tests/e2e/harness.py npm_ci only
# checks them. Labelled as e2e_ros: any run selecting it runs npm_ros first, -LE ros leaves out both.
# In the Debian 13 root (no network) tests/system/debian13.sh installs them from the host first,
# and npm_ros finds them up to date.
add_test(NAME npm_ros COMMAND /usr/bin/python3 ${CMAKE_SOURCE_DIR}/tests/npm_packages.py ${CMAKE_CURRENT_LIST_DIR})
set_tests_properties(npm_ros PROPERTIES FIXTURES_SETUP npm_ros LABELS "e2e;ros" TIMEOUT 600 SKIP_RETURN_CODE 77)
caracara_python_test(e2e_ros test_ros ${CMAKE_CURRENT_LIST_DIR} PREFIX unshare --net TIMEOUT 900 LABELS e2e ros)
set_tests_properties(e2e_ros PROPERTIES FIXTURES_REQUIRED npm_ros)
