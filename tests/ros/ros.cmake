# caracara-ros against a second DDS vendor (tests/ros/test_ros.py): a Fast DDS peer whose types
# fastddsgen makes from the published ROS 2 message definitions (npm, pinned in
# tests/ros/package-lock.json), in a private network namespace (unshare --net: loopback and
# multicast only, no packet leaves the machine). ctest -L ros.
caracara_python_test(e2e_ros test_ros ${CMAKE_CURRENT_LIST_DIR} PREFIX unshare --net TIMEOUT 900 LABELS e2e ros)
