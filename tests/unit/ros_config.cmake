# caracara-ros's settings: commands without DDS Security refused off loopback (tools/ros/ros_config).
caracara_unit_test(test_ros_config SOURCES unit/test_ros_config.cpp LIBS caracara_ros_config)
