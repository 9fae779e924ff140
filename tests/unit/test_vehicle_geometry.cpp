// core/vehicle_geometry: a Wrench in newtons through the vehicle's geometry and force curve to
// motor values, the saturation that keeps its direction, the reverse curve for pushes backwards,
// and the config's errors named by key.
#include "core/vehicle_config.hpp"

#include "core/mixing.hpp"

#include "tests/catch.hpp"
#include <cmath>

using namespace caracara;

namespace {

constexpr double kFull = 2.2 * 9.80665; // the BTD150 datasheet's 2.2 kgf

frames::BodyMotion force(double x, double y, double z) { return {{x, y, z}, {}}; }

std::string parse_error(const std::string& text) {
    VehicleGeometry g;
    return parse_vehicle(toml::parse(text), g);
}

// Eight thrusters on the body's x axis, each pushing forward (motors 0..3) or left (4..7), at the
// centre: a geometry whose pseudo-inverse is worked by hand (a force shared equally).
VehicleGeometry along_axes(ForceCurve curve) {
    std::array<ThrusterPlacement, kMotorCount> p{};
    for (std::size_t i = 0; i < kMotorCount; ++i)
        p[i] = {{0, 0, 0}, i < 4 ? frames::Vec3{1, 0, 0} : frames::Vec3{0, 1, 0}};
    return VehicleGeometry(p, std::move(curve));
}

} // namespace

TEST_CASE("a known geometry gives known motor values") {
    // 4 N forward over four forward thrusters: 1 N each, 1/10 of a 10 N curve: 885.
    const VehicleGeometry g = along_axes(ForceCurve({0, 10}, {0, 5}));
    const WrenchMotors m = g.motors_for(force(4, 0, 0));
    REQUIRE(m.ok());
    CHECK_FALSE(m.saturated);
    CHECK(m.motors == MotorValues{885, 885, 885, 885, 0, 0, 0, 0});
    // A curve of several points: 1.6 N of a {0, 4, 10} curve is 0.4 of the way to its first
    // point (at 1/2): 1/5 of full.
    const VehicleGeometry h = along_axes(ForceCurve({0, 4, 10}, {0, 4, 10}));
    CHECK(h.motors_for(force(0, 6.4, 0)).motors == MotorValues{0, 0, 0, 0, 1770, 1770, 1770, 1770});
}

TEST_CASE("negative forces take the reverse curve") {
    // 2 N backwards each on a 5 N reverse curve is 2/5 of full reverse; forwards 2/10.
    const VehicleGeometry g = along_axes(ForceCurve({0, 10}, {0, 5}));
    CHECK(g.motors_for(force(-8, 0, 0)).motors == MotorValues{-3540, -3540, -3540, -3540, 0, 0, 0, 0});
    CHECK(g.motors_for(force(8, 0, 0)).motors == MotorValues{1770, 1770, 1770, 1770, 0, 0, 0, 0});
    CHECK(g.curve().force_n(-0.4) == Approx(-2.0));
}

TEST_CASE("saturation scales every thruster by one factor: the wrench keeps its direction") {
    // 100 N forward, 20 N left: forward needs 25 N each (2.5 x full), left 5 N (0.5 x full):
    // one factor 1/2.5 makes forward full and left 0.2 of full, the ratio 5:1 kept.
    const VehicleGeometry g = along_axes(ForceCurve({0, 10}, {0, 10}));
    const WrenchMotors m = g.motors_for(force(100, 20, 0));
    REQUIRE(m.ok());
    CHECK(m.saturated);
    CHECK(m.motors == MotorValues{8850, 8850, 8850, 8850, 1770, 1770, 1770, 1770});
    // Against a weaker reverse curve the factor counts each thruster's own full thrust that way.
    const VehicleGeometry r = along_axes(ForceCurve({0, 10}, {0, 5}));
    const WrenchMotors b = r.motors_for(force(-40, 16, 0)); // 10 N of 5 back (2x), 4 N of 10 left
    CHECK(b.saturated);
    CHECK(b.motors == MotorValues{-8850, -8850, -8850, -8850, 1770, 1770, 1770, 1770});
}

TEST_CASE("the default vehicle is the seed's axis table, and its wrench is the one asked for") {
    const VehicleGeometry g;
    // Each REP 103 axis, through core/frames to the seed's axes: the signs of the seed's table.
    const MixMatrix& seed = default_mix_matrix();
    for (std::size_t k = 0; k < 6; ++k) {
        frames::BodyMotion w;
        frames::Vec3& v = k < 3 ? w.linear : w.angular;
        (k % 3 == 0 ? v.x : k % 3 == 1 ? v.y : v.z) = 1.0;
        const AxisDemand d = frames::from_flu(w);
        const WrenchMotors m = g.motors_for(w);
        REQUIRE(m.ok());
        for (std::size_t i = 0; i < kMotorCount; ++i) {
            double want = 0;
            for (std::size_t a = 0; a < kAxisCount; ++a)
                want += seed[i][a] * d[a];
            INFO("axis " << k << " motor " << i << " value " << m.motors[i]);
            CHECK((want > 0) == (m.motors[i] > 0));
            CHECK((want < 0) == (m.motors[i] < 0));
        }
    }
    // 10 N forward: the four horizontal thrusters at 45 degrees, 10 / (4 cos 45) N each, and
    // back through the curve the wrench is 10 N forward and nothing else.
    const WrenchMotors m = g.motors_for(force(10, 0, 0));
    const double each = 10 / (4 * std::sqrt(0.5)) / kFull * kMotorMax;
    for (std::size_t i : {0u, 2u, 4u, 6u})
        CHECK(m.motors[i] == Approx(each).margin(0.5));
    std::array<double, kMotorCount> fractions{};
    for (std::size_t i = 0; i < kMotorCount; ++i)
        fractions[i] = m.motors[i] / double(kMotorMax);
    const frames::BodyMotion back = g.wrench_of(fractions);
    CHECK(back.linear.x == Approx(10).epsilon(0.001));
    for (double other : {back.linear.y, back.linear.z, back.angular.x, back.angular.y, back.angular.z})
        CHECK(other == Approx(0).margin(0.01));
}

TEST_CASE("a wrench that is not a number is refused by name and moves nothing") {
    const WrenchMotors m = VehicleGeometry().motors_for({{0, 0, 0}, {0, NAN, 0}});
    CHECK(m.error == "torque.y: must be a finite number of newton-metres");
    CHECK(m.motors == MotorValues{});
}

TEST_CASE("the description is read from caracarad.toml's [vehicle] and [[thruster]] tables") {
    std::string eight;
    for (int i = 0; i < 8; ++i)
        eight += "[[thruster]]\naddress = " + std::to_string(0x52 + 2 * i) + "\nposition = [0, 0, 0]\ndirection = [" +
                 (i < 4 ? "2, 0, 0" : "0, 3, 0") + "]\n";
    VehicleGeometry g;
    REQUIRE(parse_vehicle(toml::parse("[vehicle]\nmass_kg = 12.5\ninertia_kg_m2 = [0.3, 0.5, 0.6]\n"
                                               "thrust_forward_n = [0, 10]\nthrust_reverse_n = [0, 5]\n" + eight), g) == "");
    CHECK(*g.mass_kg == 12.5);
    CHECK(g.inertia_kg_m2->z == 0.6);
    CHECK(g.placements()[0].direction.x == 1.0); // made a unit vector
    CHECK(g.motors_for(force(-8, 0, 0)).motors == MotorValues{-3540, -3540, -3540, -3540, 0, 0, 0, 0});
    // No [vehicle]: the BTD150 curve and no mass.
    VehicleGeometry d;
    REQUIRE(parse_vehicle(toml::parse(""), d) == "");
    CHECK_FALSE(d.mass_kg);
    CHECK(d.curve().full_n(true) == Approx(kFull));
}

TEST_CASE("a bad description is named by its key") {
    CHECK(parse_error("[vehicle]\nmass_kg = 0\n") ==
          "vehicle.mass_kg: must be the vehicle's mass in kg, above 0 and at most 10000");
    CHECK(parse_error("[vehicle]\nthrust_reverse_n = [0, 5, 4]\n").starts_with("vehicle.thrust_reverse_n: must rise"));
    CHECK(parse_error("[vehicle]\nthrust_forward_n = [1, 5]\n").starts_with("vehicle.thrust_forward_n: must start at 0"));
    CHECK(parse_error("[vehicle]\nmas_kg = 3\n").starts_with("vehicle.mas_kg: unknown key"));
    CHECK(parse_error("[vehicle]\ninertia_kg_m2 = [1, 2]\n").starts_with("vehicle.inertia_kg_m2: must be 3"));
    std::string some;
    for (int i = 0; i < 8; ++i)
        some += "[[thruster]]\naddress = " + std::to_string(0x52 + 2 * i) + "\n" +
                (i == 3 ? "position = [0, 0, 0]\ndirection = [1, 0, 0]\n" : "");
    CHECK(parse_error(some) == "thruster: position and direction are given for 1 of the 8 thrusters; give them for "
                               "every thruster or for none");
    std::string zero;
    for (int i = 0; i < 8; ++i)
        zero += "[[thruster]]\nposition = [0, 0, 0]\ndirection = [0, 0, " + std::string(i == 5 ? "0" : "1") + "]\n";
    CHECK(parse_error(zero).starts_with("thruster[5].direction: must be 3 numbers"));
}
