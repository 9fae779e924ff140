// A recorded dive as MCAP for rosbag2 (profile "ros2"): the topics caracara-ros publishes live
// (docs/ros2.md) with the default namespace and frames, ros2msg schemas (the Humble and Jazzy
// definitions; Range in Humble's layout) and CDR messages, so `ros2 bag info/play` opens a dive.
// Each sample gives imu, /tf, joint_states, thrusters/ordered and range/N; /diagnostics at most
// once a second; state, killed and kill_source at the start and at each change of state.
#pragma once

#include "core/dive_format.hpp"

#include <cstdint>
#include <vector>

namespace caracara::foxglove {

std::vector<uint8_t> dive_to_ros_mcap(const caracara::dive::Dive& dive);

} // namespace caracara::foxglove
