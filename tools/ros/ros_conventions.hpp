// How caracara-ros turns the vehicle's values into ROS messages, shared by the live topics
// (tools/ros/telemetry_publisher.cpp) and a recorded dive's export for rosbag2
// (tools/foxglove/dive_ros_mcap.cpp), so both say the same. Pure; no DDS.
#pragma once

#include "core/motor.hpp"

#include <cmath>
#include <cstdint>
#include <string>

namespace caracara::ros {

inline constexpr unsigned kThrusterJoints = 8;

struct Quaternion {
    double x, y, z, w;
};

// The Teensy's yaw, pitch, roll (Z, Y, X Euler angles in radians) as a quaternion.
inline Quaternion quaternion_from_ypr(double yaw, double pitch, double roll) {
    const double cy = std::cos(yaw / 2), sy = std::sin(yaw / 2);
    const double cp = std::cos(pitch / 2), sp = std::sin(pitch / 2);
    const double cr = std::cos(roll / 2), sr = std::sin(roll / 2);
    return {sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy};
}

// A motor value as a fraction of full thrust (-1..1): JointState velocities, cmd_thrust's values.
inline double motor_fraction(int32_t value) { return static_cast<double>(value) / caracara::kMotorMax; }

inline std::string thruster_joint_name(unsigned i) { return "thruster_" + std::to_string(i); }

// A distance sensor's frame, and its reading (mm) in metres.
inline std::string range_frame(std::size_t i) { return "range_" + std::to_string(i); }
inline float range_metres(uint32_t mm) { return static_cast<float>(mm) / 1000.0f; }

// std_msgs/Bool killed: the kill output is asserted in these states.
inline bool state_is_killed(const std::string& state) { return state == "killed" || state == "powered-off"; }

} // namespace caracara::ros
