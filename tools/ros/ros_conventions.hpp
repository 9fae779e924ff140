// How caracara-ros turns the vehicle's values into ROS messages, shared by the live topics
// (tools/ros/telemetry_publisher.cpp) and a recorded dive's export for rosbag2
// (tools/foxglove/dive_ros_mcap.cpp), so both say the same. Pure; no DDS. The orientation's
// conversion is core/frames.hpp's, not here.
#pragma once

#include "core/enum_names.hpp"
#include "core/frames.hpp"
#include "core/motor.hpp"

#include <cstdint>
#include <string>

namespace caracara::ros {

inline constexpr unsigned kThrusterJoints = 8;

// A ROS 2 distro's layouts where they differ on the wire: sensor_msgs/Range (Jazzy's adds
// variance) and rmw_dds_common's Gid (24 bytes in Humble, 16 since Iron).
enum class RangeLayout { Humble, Jazzy };

// What cmd_wrench's numbers are: each -1..1 of the axis's full demand (SetMotion's), or newtons
// and newton-metres through the vehicle's description (core/vehicle_geometry.hpp) to motor values.
enum class WrenchUnits { Fraction, Newton };

// caracarad announces its telemetry (the Teensy's attitude, the thrusters' readings) at 5 Hz
// (daemon/control/control_loop.cpp, kTelemetryPeriodNs): the sensor topics' default rate.
inline constexpr double kDaemonTelemetryRateHz = 5.0;
// The highest sensor rate the config takes: beyond the daemon's loop (50 Hz by default) the
// same reading would only be sent again.
inline constexpr double kMaxSensorRateHz = 50.0;

// The frame names of the defaults (REP 105): the world frame and the vehicle's body.
inline const std::string kDefaultWorldFrame = "odom";
inline const std::string kDefaultBaseFrame = "base_link";
// The IMU's frame on the vehicle (/tf_static), as ROS drivers name it.
inline const std::string kDefaultImuFrame = "imu_link";

// A frame's name in a convention (core/frames.hpp): NED / FRD frames carry _ned / _frd, as MAVROS
// names them, so a tool never takes them for REP 103's ENU / FLU ones.
inline std::string world_frame_id(const std::string& world, frames::WorldFrame f) {
    return f == frames::WorldFrame::NedFrd ? world + "_ned" : world;
}
inline std::string body_frame_id(const std::string& base, frames::WorldFrame f) {
    return f == frames::WorldFrame::NedFrd ? base + "_frd" : base;
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

namespace caracara {

template <>
struct EnumNames<ros::WrenchUnits> {
    static constexpr std::array<EnumName<ros::WrenchUnits>, 2> table{{
        {ros::WrenchUnits::Fraction, "fraction"},
        {ros::WrenchUnits::Newton, "newton"},
    }};
};
template <>
struct EnumNames<ros::RangeLayout> {
    static constexpr std::array<EnumName<ros::RangeLayout>, 2> table{{
        {ros::RangeLayout::Humble, "humble"},
        {ros::RangeLayout::Jazzy, "jazzy"},
    }};
};

} // namespace caracara
