// I2C bus-lockup recovery: caracarad on the simulator, a slave holding SDA or SCL, a kill during
// the recovery; everything checked on the simulator's side of the wire.
#include "tests/integration/daemon_on_sim.hpp"

#include <string>
#include <vector>

using namespace caracara::test;

TEST_CASE("a slave holding SDA for k = 1..9 pulses: cleared with exactly k pulses, a STOP, orders re-sent") {
    SimFixture f;
    DaemonFixture d(f, config("arming_delay_ms = 200\ncommand_timeout_ms = 60000",
                              "enabled = true\ndriver_id = \"fe804000.i2c\"\nattempts = 3\nbackoff_ms = 50"));
    const std::vector<int32_t> v = {2000, -2000, 3000, -3000, 1000, -1000, 4000, -4000};
    drive(d, f, v);

    for (uint32_t k = 1; k <= 9; ++k) {
        INFO("k = " << k);
        const uint64_t recoveries = d.bus_u64("Recoveries");
        const uint64_t stops = f.root_u64("Stops");
        const uint64_t unbinds = f.root_u64("Unbinds");
        REQUIRE(f.call(kSim, kSimIface, "ClearWireLog", "") == "");
        REQUIRE(f.call(kSim, kSimIface, "HangBus", "u", k) == "");
        REQUIRE(d.wait_for([&] { return d.bus_u64("Recoveries") == recoveries + 1; }));

        CHECK(f.root_u32("HangPulsesSeen") == k);
        CHECK(f.root_string("BusHang") == "none");
        CHECK(d.bus_u32("LastPulses") == k);
        CHECK(f.root_u64("Stops") == stops + 1);
        CHECK(f.root_u64("Unbinds") == unbinds + 1);
        CHECK(f.root_bool("DriverBound"));
        CHECK(f.root_bool("I2cFunction"));
        // No faster than 100 kHz.
        CHECK(f.root_u64("MinSclPeriodNs") >= 10000);

        // On the wire: k clock pulses, then the STOP (its own SCL rise, then SDA rising),
        // then every thruster's order again.
        auto log = f.wire_log();
        size_t pulses = 0, stop_at = log.size();
        for (size_t i = 0; i < log.size(); ++i) {
            if (log[i].bus != "i2c-lines")
                continue;
            if (log[i].result == "scl-pulse" && stop_at == log.size())
                ++pulses;
            if (log[i].result == "stop")
                stop_at = i;
        }
        REQUIRE(stop_at < log.size());
        CHECK(pulses == k + 1); // k clocks + the SCL rise that precedes the STOP
        std::vector<bool> reordered(8, false);
        for (size_t i = stop_at; i < log.size(); ++i)
            for (unsigned t = 0; t < 8; ++t)
                if (log[i].bus == "i2c" && log[i].addr == kMt[t] >> 1 && !log[i].read && log[i].result == "ack" &&
                    log[i].data.size() == 3 && log[i].data[0] == speed_byte(v[t]))
                    reordered[t] = true;
        for (unsigned t = 0; t < 8; ++t)
            CHECK(reordered[t]);
        CHECK(all_at(f, v));
        CHECK(d.vehicle_string("State") == "ready");
        CHECK(d.vehicle_string("State", "/org/caracara/Vehicle1/bus", "org.caracara.Vehicle1.Bus") == "ok");
    }
    // Clean exits: a sanitizer report or a crash would show here.
    CHECK(d.daemon.terminate() == 0);
    CHECK(f.sim.terminate() == 0);
}

TEST_CASE("SCL held low cannot be clocked free: the vehicle ends killed by the bus, reported") {
    SimFixture f;
    DaemonFixture d(f, config("arming_delay_ms = 200\ncommand_timeout_ms = 60000",
                              "enabled = true\ndriver_id = \"fe804000.i2c\"\nattempts = 2\nbackoff_ms = 20"));
    REQUIRE(d.set_thrust({1000, 0, 0, 0, 0, 0, 0, 0}) == "");
    REQUIRE(f.call(kSim, kSimIface, "HoldScl", "") == "");
    REQUIRE(d.wait_for([&] { return d.vehicle_string("State") == "killed"; }));
    CHECK(d.vehicle_string("KillSource") == "bus");
    CHECK(d.vehicle_string("State", "/org/caracara/Vehicle1/bus", "org.caracara.Vehicle1.Bus") == "lost");
    CHECK(d.bus_u64("RecoveryFailures") >= 2);
    CHECK(d.vehicle_string("LastRecoveryError", "/org/caracara/Vehicle1/bus", "org.caracara.Vehicle1.Bus").find("SCL") !=
          std::string::npos);
    CHECK(f.root_bool("KillOutput")); // the thrusters are de-energized by the kill line
    CHECK(f.root_u64("Stops") == 0);  // never a STOP: clocking was not even tried
    // The bus comes back later (the background retries find it): the thrusters get zeros.
    REQUIRE(f.call(kSim, kSimIface, "ReleaseBus", "") == "");
    REQUIRE(d.wait_for([&] { return d.bus_u64("Recoveries") == 1; }, 15000));
    CHECK(f.thruster_byte(0, "OrderedSpeed") == 0x80);
    CHECK(d.vehicle_string("State") == "killed"); // a recovery never clears a kill
    // Clean exits: a sanitizer report or a crash would show here.
    CHECK(d.daemon.terminate() == 0);
    CHECK(f.sim.terminate() == 0);
}

TEST_CASE("a kill that arrives during recovery reaches every thruster first once the bus is back") {
    SimFixture f;
    DaemonFixture d(f, config("arming_delay_ms = 200\ncommand_timeout_ms = 60000",
                              "enabled = true\ndriver_id = \"fe804000.i2c\"\nattempts = 5\nbackoff_ms = 400"));
    const std::vector<int32_t> v = {3000, 3000, 3000, 3000, 0, 0, 0, 0};
    drive(d, f, v);
    // SCL stuck: the first attempt fails and the daemon backs off; the kill lands meanwhile.
    REQUIRE(f.call(kSim, kSimIface, "HoldScl", "") == "");
    REQUIRE(d.wait_for([&] { return d.bus_u64("RecoveryFailures") >= 1; }));
    REQUIRE(d.call("Kill", "") == "");
    CHECK(d.vehicle_string("State") == "killed");
    REQUIRE(f.call(kSim, kSimIface, "ClearWireLog", "") == "");
    REQUIRE(f.call(kSim, kSimIface, "ReleaseBus", "") == "");
    REQUIRE(d.wait_for([&] { return d.bus_u64("Recoveries") == 1; }));
    // The first order each thruster receives after the recovery is zero.
    auto log = f.wire_log();
    std::vector<int> first(8, -1);
    for (const auto& e : log)
        for (unsigned t = 0; t < 8; ++t)
            if (e.bus == "i2c" && e.addr == kMt[t] >> 1 && !e.read && e.result == "ack" && e.data.size() == 3 && first[t] < 0)
                first[t] = e.data[0];
    for (unsigned t = 0; t < 8; ++t) {
        INFO("thruster " << t);
        CHECK(first[t] == 0x80);
        CHECK(f.thruster_byte(t, "OrderedSpeed") == 0x80);
    }
    CHECK(d.set_thrust(v) == "org.caracara.Vehicle1.Error.Killed");
    // Clean exits: a sanitizer report or a crash would show here.
    CHECK(d.daemon.terminate() == 0);
    CHECK(f.sim.terminate() == 0);
}
