# caracara-ros against a second DDS vendor (tests/ros/test_ros.py): a Fast DDS peer whose types
# fastddsgen makes from the published ROS 2 message definitions (npm, pinned in
# tests/ros/package-lock.json), in a private network namespace (unshare --net: loopback and
# multicast only, no packet leaves the machine). ctest -L ros.
add_test(NAME e2e_ros
         COMMAND unshare --net /usr/bin/python3 -m unittest -v test_ros
         WORKING_DIRECTORY ${CMAKE_CURRENT_LIST_DIR})
set_tests_properties(e2e_ros PROPERTIES
                     ENVIRONMENT "CARACARA_BUILD_DIR=${CMAKE_BINARY_DIR};PYTHONDONTWRITEBYTECODE=1;${CARACARA_TEST_ENV}"
                     TIMEOUT 900
                     LABELS "e2e;ros")
