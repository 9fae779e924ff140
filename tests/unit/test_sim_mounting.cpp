// The simulator's commissioning knobs ([sim] in its TOML): thrusters mounted reversed or
// disconnected change what the body does with the same orders on the wire, and the Teensy's
// orientation answers carry noise and a slow drift while the body's attitude stays the truth.
#include "sim/sim_config.hpp"
#include "sim/sim_vehicle.hpp"

#include "tests/catch.hpp"

#include <cmath>
#include <string>

using namespace caracara::sim;

namespace {

SimConfig parsed(const std::string& text) {
    SimConfig c;
    std::string err;
    REQUIRE(parse_sim_config(text, c, err));
    return c;
}

// Orders SPEED on motor i as the daemon would: [SPEED, INFO, CSUM] to its address.
void order(SimVehicle& v, size_t i, uint8_t speed) {
    ThrusterModel& t = *v.thrusters()[i];
    const uint8_t mt = static_cast<uint8_t>(t.addr7() << 1);
    const uint8_t msg[3] = {speed, 100, static_cast<uint8_t>(mt + speed + 100)};
    t.on_write(msg, 0);
}

double yaw_after_pushing(SimVehicle& v, size_t motor) {
    order(v, motor, 0xA0); // forward
    for (int k = 0; k < 100; ++k)
        v.step(0.01, uint64_t(k) * 10'000'000ull);
    return v.body().yaw();
}

} // namespace

TEST_CASE("a thruster mounted reversed turns the body the other way for the same order") {
    // Motor 0 has +1 in the yaw column of the seed's axis table.
    SimVehicle normal(parsed(""));
    SimVehicle reversed(parsed("[sim]\nreversed_thrusters = [0, 5]\n"));
    const double a = yaw_after_pushing(normal, 0);
    const double b = yaw_after_pushing(reversed, 0);
    CHECK(a > 0.01);
    CHECK(b < -0.01);
    CHECK(std::abs(a + b) < 1e-9);
}

TEST_CASE("a disconnected thruster answers on the bus but pushes nothing") {
    SimVehicle v(parsed("[sim]\ndisconnected_thrusters = [2]\n"));
    CHECK(yaw_after_pushing(v, 2) == 0.0);
    CHECK(v.thrusters()[2]->actual_fraction() > 0.1);
}

TEST_CASE("orientation answers carry noise and drift; the body stays the truth") {
    SimVehicle v(parsed("[sim]\norientation_noise_rad = 0.01\nyaw_drift_rad_s = 0.002\nnoise_seed = 7\n"));
    for (int k = 0; k < 1000; ++k)
        v.step(0.01, uint64_t(k) * 10'000'000ull);
    CHECK(v.body().yaw() == 0.0);
    CHECK(v.teensy().orientation().yaw == Approx(0.02).margin(1e-9));
    double sum = 0.0, sq = 0.0;
    const int n = 2000;
    for (int k = 0; k < n; ++k) {
        const double e = v.teensy().measured_orientation().pitch;
        sum += e;
        sq += e * e;
    }
    const double mean = sum / n;
    const double sd = std::sqrt(sq / n - mean * mean);
    CHECK(std::abs(mean) < 0.002);
    CHECK(sd == Approx(0.01).margin(0.001));
}

TEST_CASE("bad commissioning keys are refused with the key named") {
    SimConfig c;
    std::string err;
    CHECK_FALSE(parse_sim_config("[sim]\nreversed_thrusters = [8]\n", c, err));
    CHECK(err.find("sim.reversed_thrusters") != std::string::npos);
    CHECK_FALSE(parse_sim_config("[sim]\norientation_noise_rad = -1.0\n", c, err));
    CHECK(err.find("sim.orientation_noise_rad") != std::string::npos);
}
