// The vehicle's frames: the one place that says which way each interface's axes point and that
// converts between them (docs/frames.md draws them). Every edge converts here and nowhere else.
//
// The D-Bus contract (SetMotion's AxisDemand, the Teensy's Orientation) keeps the Caracara packet
// seed's axes ("caracara-usb-packet", axis table), core/mixing.hpp:
//   x + towards port, y + forward, z + deeper,
//   yaw + clockwise seen from above, pitch + nose up, roll + clockwise seen from behind
//   (right side down).
// The Teensy reports its angles the same way (Teensy SPI protocol, Get orientation: yaw is the
// heading, clockwise from its reference direction).
//
// The other edges speak their users' conventions:
//   REP 103 body FLU   x forward, y left, z up; rotations right-handed about each axis
//                      (ROS 2, Foxglove).
//   REP 103 body FRD   x forward, y right, z down (the `_frd` frames, where a config asks).
//   World ENU          x east, y north, z up (REP 103 / 145). The heading reference (yaw 0 of the
//                      Teensy, north for a compass-referenced sensor) is ENU's +y, so the ENU yaw
//                      of base_link is pi/2 - heading: a clockwise turn decreases it.
//   World NED          x north (the heading reference), y east, z down: the FRD body's yaw is the
//                      heading itself.
//   Pilot's words      forward, starboard, up, turn right, nose up, roll right (the cockpit,
//                      caracaractl).
#pragma once

#include "core/enum_names.hpp"
#include "core/mixing.hpp"

#include <array>
#include <optional>
#include <string_view>

namespace caracara::frames {

struct Vec3 {
    double x = 0, y = 0, z = 0;
};

// A motion demand (or a wrench) in a right-handed body frame: linear along, angular about x, y, z.
struct BodyMotion {
    Vec3 linear;
    Vec3 angular;
};

// REP 103 body FLU (ROS 2 geometry_msgs/Wrench and Twist, Foxglove).
AxisDemand from_flu(const BodyMotion& m);
BodyMotion to_flu(const AxisDemand& d);
// Body FRD (x forward, y right, z down).
AxisDemand from_frd(const BodyMotion& m);
BodyMotion to_frd(const AxisDemand& d);

// A motion in a pilot's words; each -1..1, a negative value the opposite motion.
struct PilotMotion {
    double forward = 0;     // - backward
    double starboard = 0;   // - towards port
    double up = 0;          // - down (deeper)
    double turn_right = 0;  // clockwise seen from above
    double nose_up = 0;
    double roll_right = 0;  // right side down
};
enum class PilotAxis { Forward, Starboard, Up, TurnRight, NoseUp, RollRight };
AxisDemand from_pilot(const PilotMotion& m);
PilotMotion to_pilot(const AxisDemand& d);
double& pilot_axis(PilotMotion& m, PilotAxis a);

// The Teensy's (and the D-Bus Orientation's) angles, radians.
struct Attitude {
    double heading = 0;  // yaw: clockwise seen from above, from the heading reference
    double pitch = 0;    // nose up
    double roll = 0;     // right side down
};

struct Quaternion {
    double x = 0, y = 0, z = 0, w = 1;
};

// Which world and body a published orientation is in.
enum class WorldFrame {
    EnuFlu,  // REP 103 / 145: base_link (FLU) in odom (ENU); ROS 2 and Foxglove by default
    NedFrd,  // base_link_frd in odom_ned, where a config asks for it
};
// The body's orientation in the world frame (body to world rotation).
Quaternion orientation(const Attitude& a, WorldFrame frame);
// A rotation of the body given as yaw, pitch, roll in that frame's own sense (right-handed
// Z-Y-X Euler angles): what orientation() builds on, and what tests read back.
Quaternion from_euler_zyx(double yaw, double pitch, double roll);
// Yaw about the world's z of a body-to-world rotation (right-handed, radians in (-pi, pi]).
double yaw_of(const Quaternion& q);

} // namespace caracara::frames

namespace caracara {

template <>
struct EnumNames<frames::PilotAxis> {
    // The names the cockpit's messages and caracaractl's arguments use.
    static constexpr std::array<EnumName<frames::PilotAxis>, 6> table{{
        {frames::PilotAxis::Forward, "forward"},
        {frames::PilotAxis::Starboard, "starboard"},
        {frames::PilotAxis::Up, "up"},
        {frames::PilotAxis::TurnRight, "turn_right"},
        {frames::PilotAxis::NoseUp, "nose_up"},
        {frames::PilotAxis::RollRight, "roll_right"},
    }};
};
template <>
struct EnumNames<frames::WorldFrame> {
    static constexpr std::array<EnumName<frames::WorldFrame>, 2> table{{
        {frames::WorldFrame::EnuFlu, "enu"},
        {frames::WorldFrame::NedFrd, "ned"},
    }};
};

} // namespace caracara
