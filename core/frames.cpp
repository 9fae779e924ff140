#include "core/frames.hpp"

#include <cmath>
#include <numbers>

namespace caracara::frames {

namespace {
constexpr std::size_t ix(Axis a) { return static_cast<std::size_t>(a); }
} // namespace

// FLU -> the seed's axes: port is +y (left), forward +x, deeper -z; clockwise from above is a
// negative rotation about up, nose up a negative one about left, right side down a positive
// one about forward.
AxisDemand from_flu(const BodyMotion& m) {
    AxisDemand d{};
    d[ix(Axis::X)] = m.linear.y;
    d[ix(Axis::Y)] = m.linear.x;
    d[ix(Axis::Z)] = -m.linear.z;
    d[ix(Axis::Yaw)] = -m.angular.z;
    d[ix(Axis::Pitch)] = -m.angular.y;
    d[ix(Axis::Roll)] = m.angular.x;
    return d;
}

BodyMotion to_flu(const AxisDemand& d) {
    return {{d[ix(Axis::Y)], d[ix(Axis::X)], -d[ix(Axis::Z)]},
            {d[ix(Axis::Roll)], -d[ix(Axis::Pitch)], -d[ix(Axis::Yaw)]}};
}

// FRD is FLU with y and z turned over: right is -port, down is deeper; right-handed about down
// is clockwise from above, about right is nose up.
AxisDemand from_frd(const BodyMotion& m) {
    return from_flu({{m.linear.x, -m.linear.y, -m.linear.z}, {m.angular.x, -m.angular.y, -m.angular.z}});
}

BodyMotion to_frd(const AxisDemand& d) {
    const BodyMotion f = to_flu(d);
    return {{f.linear.x, -f.linear.y, -f.linear.z}, {f.angular.x, -f.angular.y, -f.angular.z}};
}

AxisDemand from_pilot(const PilotMotion& m) {
    AxisDemand d{};
    d[ix(Axis::X)] = -m.starboard;
    d[ix(Axis::Y)] = m.forward;
    d[ix(Axis::Z)] = -m.up;
    d[ix(Axis::Yaw)] = m.turn_right;
    d[ix(Axis::Pitch)] = m.nose_up;
    d[ix(Axis::Roll)] = m.roll_right;
    return d;
}

PilotMotion to_pilot(const AxisDemand& d) {
    return {d[ix(Axis::Y)], -d[ix(Axis::X)], -d[ix(Axis::Z)], d[ix(Axis::Yaw)], d[ix(Axis::Pitch)], d[ix(Axis::Roll)]};
}

double& pilot_axis(PilotMotion& m, PilotAxis a) {
    switch (a) {
    case PilotAxis::Forward: return m.forward;
    case PilotAxis::Starboard: return m.starboard;
    case PilotAxis::Up: return m.up;
    case PilotAxis::TurnRight: return m.turn_right;
    case PilotAxis::NoseUp: return m.nose_up;
    case PilotAxis::RollRight: break;
    }
    return m.roll_right;
}

Quaternion from_euler_zyx(double yaw, double pitch, double roll) {
    const double cy = std::cos(yaw / 2), sy = std::sin(yaw / 2);
    const double cp = std::cos(pitch / 2), sp = std::sin(pitch / 2);
    const double cr = std::cos(roll / 2), sr = std::sin(roll / 2);
    return {sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy};
}

Quaternion orientation(const Attitude& a, WorldFrame frame) {
    // NED / FRD: the Teensy's angles are that frame's Z-Y-X Euler angles as they are. ENU / FLU
    // (REP 103): yaw from east counter-clockwise, so pi/2 - heading; nose up is a negative
    // rotation about the left axis; roll right is positive about forward in both.
    if (frame == WorldFrame::NedFrd)
        return from_euler_zyx(a.heading, a.pitch, a.roll);
    return from_euler_zyx(std::numbers::pi / 2 - a.heading, -a.pitch, a.roll);
}

double yaw_of(const Quaternion& q) {
    return std::atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
}

} // namespace caracara::frames
