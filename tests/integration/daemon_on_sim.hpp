// What the integration tests of caracarad on the simulator share: the simulator's GPIO lines in
// a daemon configuration, the speed byte a motor value becomes, and driving the thrusters
// until the simulator's side of the wire holds the command.
#pragma once

#include "tests/integration/daemon_fixture.hpp"
#include "tests/integration/sim_fixture.hpp"

#include "tests/catch.hpp"

#include <cstdint>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

namespace caracara::test {


inline constexpr uint8_t kMt[8] = {0x52, 0x56, 0x58, 0x5A, 0x5C, 0x5E, 0x60, 0x62};
// Lines of the simulator's gpiochip0 (sim/gpio_model.hpp: KILL_OUT, POWER_OFF).
inline constexpr uint16_t kKillOutLine = 27;
inline constexpr uint16_t kPowerOffLine = 22;

// The simulator's GPIO chip: I2C1 on GPIO2/3, the kill switch, kill and power-off outputs.
inline const std::string kGpioConfig = R"(
[gpio]
kill_switch = { line = "KILL_SWITCH" }
kill_output = { line = "KILL_OUT" }
power_off_output = { line = "POWER_OFF" }
scl = { line = "GPIO3" }
sda = { line = "GPIO2" }
)";

inline std::string config(const std::string& control, const std::string& recovery) {
    return "[control]\n" + control + "\n" + kGpioConfig + "\n[recovery]\n" + recovery + "\n";
}

inline uint8_t speed_byte(int v) {
    const int steps = (std::abs(v) * 102 + 4425) / 8850;
    if (steps == 0)
        return 0x80;
    return static_cast<uint8_t>(v > 0 ? 0x80 + steps : 0x7F - steps);
}

inline const std::string kSim = "/org/caracara/Simulator1";
inline constexpr const char* kSimIface = "org.caracara.Simulator1";

inline bool all_at(SimFixture& f, const std::vector<int32_t>& v) {
    for (unsigned i = 0; i < 8; ++i)
        if (f.thruster_byte(i, "OrderedSpeed") != speed_byte(v[i]))
            return false;
    return true;
}

// Commands `v` and waits until every simulated thruster holds it.
inline void drive(DaemonFixture& d, SimFixture& f, const std::vector<int32_t>& v) {
    REQUIRE(d.set_thrust(v) == "");
    REQUIRE(d.wait_for([&] { return all_at(f, v); }));
}

inline uint64_t now_ns() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<uint64_t>(ts.tv_sec) * 1000000000ull + static_cast<uint64_t>(ts.tv_nsec);
}
} // namespace caracara::test
