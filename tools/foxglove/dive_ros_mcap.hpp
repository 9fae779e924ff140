// A recorded dive as MCAP for rosbag2 (profile "ros2"): the topics caracara-ros publishes live
// (docs/ros2.md) with the default namespace and frames, ros2msg schemas (Range in `distro`'s
// layout) and CDR messages, so `ros2 bag info/play` opens a dive and replays it as recorded: each
// channel carries the QoS caracara-ros offers (offered_qos_profiles, as rosbag2 writes them; the
// state topics transient-local), and a "rosbag2" metadata record names the ROS_DISTRO.
// Each sample gives imu, /tf, joint_states, thrusters/ordered and range/N; /diagnostics at most
// once a second; state, killed and kill_source at the start and at each change of state.
#pragma once

#include "core/dive_format.hpp"
#include "tools/ros/ros_conventions.hpp"

#include <cstdint>
#include <vector>

namespace caracara::foxglove {

std::vector<uint8_t> dive_to_ros_mcap(const caracara::dive::Dive& dive,
                                      caracara::ros::RangeLayout distro = caracara::ros::RangeLayout::Humble);

} // namespace caracara::foxglove
