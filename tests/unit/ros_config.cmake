# caracara-ros's settings: commands without DDS Security refused off loopback (tools/ros/ros_config);
# what a Range subscriber's USER_DATA asks for (tools/ros/range_subscribers: its parsing, no DDS run).
caracara_unit_test(test_ros_config SOURCES unit/test_ros_config.cpp unit/test_range_subscribers.cpp
                   LIBS caracara_ros_config caracara_ros_range)
