// core/frames: each edge's axes judged by what the seed's axis table does with them (the motors
// it turns, with their signs), and each orientation by where it points the body's axes in the
// world, never by the module's own inverse alone.
#include "core/frames.hpp"

#include "tests/catch.hpp"
#include <cmath>
#include <numbers>
#include <set>

using namespace caracara;
using namespace caracara::frames;

namespace {

struct MotorSigns {
    std::set<std::size_t> positive, negative;
};

// The motors a demand turns, read from the mix (the seed's axis table).
MotorSigns motors_of(const AxisDemand& d) {
    const MixResult r = mix(d);
    REQUIRE(r.ok());
    MotorSigns s;
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        if (r.motors[i] > 0)
            s.positive.insert(i);
        else if (r.motors[i] < 0)
            s.negative.insert(i);
    }
    return s;
}

// The seed's words for each motion ("caracara-usb-packet", axis table).
const MotorSigns kForward{{0, 2, 4, 6}, {}};
const MotorSigns kBackward{{}, {0, 2, 4, 6}};
const MotorSigns kPort{{2, 6}, {0, 4}};
const MotorSigns kStarboard{{0, 4}, {2, 6}};
const MotorSigns kDeeper{{1, 3, 5, 7}, {}};
const MotorSigns kUp{{}, {1, 3, 5, 7}};
const MotorSigns kClockwise{{0, 2}, {4, 6}};
const MotorSigns kCounterClockwise{{4, 6}, {0, 2}};
const MotorSigns kNoseUp{{3, 5}, {1, 7}};
const MotorSigns kNoseDown{{1, 7}, {3, 5}};
const MotorSigns kRollRight{{5, 7}, {1, 3}};  // clockwise seen from behind
const MotorSigns kRollLeft{{1, 3}, {5, 7}};

BodyMotion lin(Vec3 v) { return BodyMotion{v, Vec3{}}; }
BodyMotion ang(Vec3 v) { return BodyMotion{Vec3{}, v}; }

void same(const MotorSigns& got, const MotorSigns& want) {
    CHECK(got.positive == want.positive);
    CHECK(got.negative == want.negative);
}

Vec3 rotate(const Quaternion& q, const Vec3& v) {
    // v' = q v q*, written out.
    const double ux = q.x, uy = q.y, uz = q.z, s = q.w;
    const double dot_uv = ux * v.x + uy * v.y + uz * v.z, dot_uu = ux * ux + uy * uy + uz * uz;
    const Vec3 cross{uy * v.z - uz * v.y, uz * v.x - ux * v.z, ux * v.y - uy * v.x};
    return {2 * dot_uv * ux + (s * s - dot_uu) * v.x + 2 * s * cross.x,
            2 * dot_uv * uy + (s * s - dot_uu) * v.y + 2 * s * cross.y,
            2 * dot_uv * uz + (s * s - dot_uu) * v.z + 2 * s * cross.z};
}

void near(const Vec3& got, const Vec3& want) {
    CHECK(got.x == Approx(want.x).margin(1e-9));
    CHECK(got.y == Approx(want.y).margin(1e-9));
    CHECK(got.z == Approx(want.z).margin(1e-9));
}

} // namespace

TEST_CASE("a pilot's words move the vehicle as the seed names the motion") {
    same(motors_of(from_pilot({.forward = 0.5})), kForward);
    same(motors_of(from_pilot({.forward = -0.5})), kBackward);
    same(motors_of(from_pilot({.starboard = 0.5})), kStarboard);
    same(motors_of(from_pilot({.starboard = -0.5})), kPort);
    same(motors_of(from_pilot({.up = 0.5})), kUp);
    same(motors_of(from_pilot({.up = -0.5})), kDeeper);
    same(motors_of(from_pilot({.turn_right = 0.5})), kClockwise);
    same(motors_of(from_pilot({.nose_up = 0.5})), kNoseUp);
    same(motors_of(from_pilot({.roll_right = 0.5})), kRollRight);
}

TEST_CASE("REP 103 body FLU: x forward, y left, z up, rotations right-handed") {
    same(motors_of(from_flu(lin(Vec3{0.5, 0, 0}))), kForward);
    same(motors_of(from_flu(lin(Vec3{0, 0.5, 0}))), kPort);
    same(motors_of(from_flu(lin(Vec3{0, 0, 0.5}))), kUp);
    same(motors_of(from_flu(ang(Vec3{0, 0, 0.5}))), kCounterClockwise);  // positive yaw: to the left
    same(motors_of(from_flu(ang(Vec3{0, 0.5, 0}))), kNoseDown);          // positive pitch about left
    same(motors_of(from_flu(ang(Vec3{0.5, 0, 0}))), kRollRight);         // positive roll about forward
}

TEST_CASE("body FRD: x forward, y right, z down, rotations right-handed") {
    same(motors_of(from_frd(lin(Vec3{0.5, 0, 0}))), kForward);
    same(motors_of(from_frd(lin(Vec3{0, 0.5, 0}))), kStarboard);
    same(motors_of(from_frd(lin(Vec3{0, 0, 0.5}))), kDeeper);
    same(motors_of(from_frd(ang(Vec3{0, 0, 0.5}))), kClockwise);
    same(motors_of(from_frd(ang(Vec3{0, 0.5, 0}))), kNoseUp);
    same(motors_of(from_frd(ang(Vec3{0.5, 0, 0}))), kRollRight);
}

TEST_CASE("every conversion comes back to the same demand") {
    const AxisDemand d{0.1, -0.2, 0.3, -0.4, 0.5, -0.6};
    CHECK(from_flu(to_flu(d)) == d);
    CHECK(from_frd(to_frd(d)) == d);
    CHECK(from_pilot(to_pilot(d)) == d);
    PilotMotion p;
    for (const auto& n : EnumNames<PilotAxis>::table)
        pilot_axis(p, n.value) = 0.25;
    CHECK(p.forward == 0.25);
    CHECK(p.roll_right == 0.25);
}

TEST_CASE("ENU / FLU orientation: where the body's axes point in the world") {
    const double q = std::numbers::pi / 2;
    // Heading 0 faces the heading reference, north: ENU's +y.
    near(rotate(orientation({}, WorldFrame::EnuFlu), {1, 0, 0}), {0, 1, 0});
    near(rotate(orientation({}, WorldFrame::EnuFlu), {0, 1, 0}), {-1, 0, 0});  // left is west
    // Heading 90 degrees clockwise faces east.
    near(rotate(orientation({.heading = q}, WorldFrame::EnuFlu), {1, 0, 0}), {1, 0, 0});
    // Nose up lifts the forward axis; roll right lifts the left side.
    CHECK(rotate(orientation({.pitch = 0.3}, WorldFrame::EnuFlu), {1, 0, 0}).z == Approx(std::sin(0.3)));
    CHECK(rotate(orientation({.roll = 0.3}, WorldFrame::EnuFlu), {0, 1, 0}).z == Approx(std::sin(0.3)));
    // A clockwise turn decreases the ENU yaw (REP 103: counter-clockwise positive).
    const double before = yaw_of(orientation({.heading = 0.2}, WorldFrame::EnuFlu));
    const double after = yaw_of(orientation({.heading = 0.7}, WorldFrame::EnuFlu));
    CHECK(after - before == Approx(-0.5));
}

TEST_CASE("NED / FRD orientation: the Teensy's angles as they are") {
    near(rotate(orientation({}, WorldFrame::NedFrd), {1, 0, 0}), {1, 0, 0});
    near(rotate(orientation({.heading = std::numbers::pi / 2}, WorldFrame::NedFrd), {1, 0, 0}), {0, 1, 0});
    // Nose up: forward points against down; roll right: the right axis points down.
    CHECK(rotate(orientation({.pitch = 0.3}, WorldFrame::NedFrd), {1, 0, 0}).z == Approx(-std::sin(0.3)));
    CHECK(rotate(orientation({.roll = 0.3}, WorldFrame::NedFrd), {0, 1, 0}).z == Approx(std::sin(0.3)));
    CHECK(yaw_of(orientation({.heading = 0.7}, WorldFrame::NedFrd)) == Approx(0.7));
}
