// A recorded dive as MCAP for rosbag2 (profile "ros2"): the topics caracara-ros publishes live
// (docs/ros2.md) under the settings' namespace and frames (caracara-ros's [ros] config, the same
// rules: ros_topic, the frame convention, each sensor's mount and /tf_static), ros2msg schemas (Range in `distro`'s
// layout) and CDR messages, so `ros2 bag info/play` opens a dive and replays it as recorded: each
// channel carries the QoS caracara-ros offers (offered_qos_profiles, as rosbag2 writes them; the
// state topics transient-local), and a "rosbag2" metadata record names the ROS_DISTRO.
// Each sample gives imu, /tf, joint_states, thrusters/ordered and range/N; /diagnostics at most
// once a second; state, killed and kill_source at the start and at each change of state;
// /tf_static (the IMU's and each distance sensor's mount) once at the start.
#pragma once

#include "core/dive_format.hpp"
#include "tools/ros/ros_config.hpp"

#include <cstdint>
#include <vector>

namespace caracara::foxglove {

std::vector<uint8_t> dive_to_ros_mcap(const caracara::dive::Dive& dive, const caracara::ros::RosConfig& config,
                                      caracara::ros::RangeLayout distro = caracara::ros::RangeLayout::Humble);

} // namespace caracara::foxglove
