// The kill switch and the kill and power-off outputs: caracarad on the simulator, everything
// checked on the simulator's GPIO lines and wire.
#include "tests/integration/daemon_on_sim.hpp"

#include <algorithm>
#include <chrono>
#include <map>
#include <string>
#include <thread>
#include <vector>

using namespace caracara::test;

TEST_CASE("the kill switch kills at its edge, not at the next tick, and blocks arming while set") {
    SimFixture f;
    // A 1 Hz loop: a kill found by polling at the tick could take a whole second.
    DaemonFixture d(f, config("loop_rate_hz = 1\narming_delay_ms = 200\ncommand_timeout_ms = 60000", "enabled = false"));
    const std::vector<int32_t> v = {2500, 2500, 2500, 2500, 2500, 2500, 2500, 2500};
    drive(d, f, v);
    CHECK_FALSE(f.root_bool("KillOutput"));

    REQUIRE(f.call(kSim, kSimIface, "ClearWireLog", "") == "");
    const uint64_t t0 = now_ns();
    REQUIRE(f.call(kSim, kSimIface, "SetKillSwitch", "b", 1) == "");
    REQUIRE(d.wait_for([&] { return all_at(f, std::vector<int32_t>(8, 0)); }, 3000));
    const uint64_t t1 = now_ns();
    CHECK((t1 - t0) < 500'000'000ull); // well inside one 1 s tick: the edge did it
    CHECK(d.vehicle_string("State") == "killed");
    CHECK(d.vehicle_string("KillSource") == "switch");
    CHECK(f.root_bool("KillOutput"));

    // The simulator's wire log has the edge: bus "gpio", the switch's line offset, its new
    // level on the wire (active high here), stamped inside the call and before the zero order
    // of every thruster; the kill output the daemon drives follows it.
    const uint32_t line = f.root_u32("KillSwitchLine");
    CHECK_FALSE(f.root_bool("KillSwitchActiveLow"));
    const auto log = f.wire_log();
    size_t edge = log.size();
    for (size_t i = 0; i < log.size() && edge == log.size(); ++i)
        if (log[i].bus == "gpio" && log[i].addr == line)
            edge = i;
    REQUIRE(edge < log.size());
    CHECK(log[edge].data == std::vector<uint8_t>{1});
    CHECK(log[edge].result == "edge");
    CHECK(log[edge].time_ns >= t0);
    CHECK(log[edge].time_ns <= t1);
    for (unsigned t = 0; t < 8; ++t) {
        INFO("thruster " << t);
        size_t zero = log.size();
        for (size_t i = 0; i < log.size() && zero == log.size(); ++i)
            if (log[i].bus == "i2c" && log[i].addr == kMt[t] >> 1 && !log[i].read && log[i].result == "ack" &&
                log[i].data.size() == 3 && log[i].data[0] == 0x80)
                zero = i;
        REQUIRE(zero < log.size());
        CHECK(zero > edge);
        CHECK(log[zero].time_ns >= log[edge].time_ns);
    }
    bool kill_out = false;
    for (size_t i = edge; i < log.size(); ++i)
        if (log[i].bus == "gpio" && log[i].addr == kKillOutLine && log[i].data == std::vector<uint8_t>{1})
            kill_out = log[i].time_ns >= log[edge].time_ns;
    CHECK(kill_out);

    CHECK(d.call("ClearKill", "") == "org.caracara.Vehicle1.Error.KillSwitchSet");
    CHECK(d.vehicle_string("State") == "killed");
    CHECK(d.set_thrust(v) == "org.caracara.Vehicle1.Error.Killed");
    CHECK(all_at(f, std::vector<int32_t>(8, 0)));

    // Released: still killed until an explicit ClearKill, then arming with zero output.
    REQUIRE(f.call(kSim, kSimIface, "SetKillSwitch", "b", 0) == "");
    REQUIRE(d.wait_for([&] { return true; }, 100));
    CHECK(d.vehicle_string("State") == "killed");
    REQUIRE(d.call("ClearKill", "") == "");
    CHECK(d.vehicle_string("State") == "arming");
    CHECK_FALSE(f.root_bool("KillOutput"));
    CHECK(d.set_thrust(v) == "org.caracara.Vehicle1.Error.Arming");
    REQUIRE(d.wait_for([&] { return d.vehicle_string("State") == "ready"; }, 5000));
    drive(d, f, v);
    // Clean exits: a sanitizer report or a crash would show here.
    CHECK(d.daemon.terminate() == 0);
    CHECK(f.sim.terminate() == 0);
}

TEST_CASE("a kill switch already set at start: the daemon comes up killed") {
    SimFixture f;
    REQUIRE(f.call(kSim, kSimIface, "SetKillSwitch", "b", 1) == "");
    DaemonFixture d(f, config("arming_delay_ms = 200", "enabled = false"), false);
    CHECK(d.vehicle_string("State") == "killed");
    CHECK(d.vehicle_string("KillSource") == "switch");
    CHECK(f.root_bool("KillOutput"));
    // Clean exits: a sanitizer report or a crash would show here.
    CHECK(d.daemon.terminate() == 0);
    CHECK(f.sim.terminate() == 0);
}

TEST_CASE("a confirmed power-off asserts the power-off line after zeroing the thrusters") {
    SimFixture f;
    DaemonFixture d(f, config("arming_delay_ms = 200\ncommand_timeout_ms = 60000", "enabled = false"));
    // All eight running: a thruster at zero is refreshed with zero orders, which are not the
    // power-off's.
    REQUIRE(d.set_thrust(std::vector<int32_t>(8, 1000)) == "");
    CHECK(d.call("PowerOff", "s", "yes") == "org.caracara.Vehicle1.Error.ConfirmationRequired");
    CHECK_FALSE(f.root_bool("PowerOffOutput"));
    REQUIRE(f.call(kSim, kSimIface, "ClearWireLog", "") == "");
    REQUIRE(d.call("PowerOff", "s", "power-off") == "");
    // The zero orders are on the wire before the power-off line moves (judged by the order
    // of the wire log's entries, not their stamps).
    REQUIRE(d.wait_for([&] { return f.root_bool("PowerOffOutput"); }));
    CHECK(all_at(f, std::vector<int32_t>(8, 0)));
    const auto log = f.wire_log();
    // Each thruster's first zero order is the power-off's; later ones are the refreshes of a
    // vehicle at zero, which go on after the line moved (a slow machine reads them too).
    std::map<uint16_t, uint64_t> first_zero;
    uint64_t power_off_edge = 0;
    for (const auto& e : log) {
        if (e.bus == "i2c" && !e.read && e.result == "ack" && e.data.size() == 3 && e.data[0] == speed_byte(0))
            first_zero.emplace(e.addr, e.index);
        if (e.bus == "gpio" && e.addr == kPowerOffLine && power_off_edge == 0)
            power_off_edge = e.index;
    }
    uint64_t last_zero = 0;
    for (const auto& [addr, index] : first_zero)
        last_zero = std::max(last_zero, index);
    INFO("the eighth thruster's first zero order #" << last_zero << ", then line edge #" << power_off_edge);
    CHECK(first_zero.size() == 8);
    CHECK(power_off_edge > last_zero);
    CHECK(d.vehicle_string("State") == "powered-off");
    // Clean exits: a sanitizer report or a crash would show here.
    CHECK(d.daemon.terminate() == 0);
    CHECK(f.sim.terminate() == 0);
}
