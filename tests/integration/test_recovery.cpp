// I2C bus-lockup recovery, the kill switch and the kill / power-off outputs: caracarad on the
// simulator, everything checked on the simulator's side of the wire.
#include "tests/integration/daemon_fixture.hpp"
#include "tests/integration/sim_fixture.hpp"

#include "tests/catch.hpp"
#include <csignal>
#include <chrono>
#include <ctime>
#include <fstream>
#include <string>
#include <thread>

using namespace caracara::test;

namespace {

constexpr uint8_t kMt[8] = {0x52, 0x56, 0x58, 0x5A, 0x5C, 0x5E, 0x60, 0x62};
// Lines of the simulator's gpiochip0 (sim/gpio_model.hpp: KILL_OUT, POWER_OFF).
constexpr uint16_t kKillOutLine = 27;
constexpr uint16_t kPowerOffLine = 22;

// The simulator's GPIO chip: I2C1 on GPIO2/3, the kill switch, kill and power-off outputs.
const std::string kGpioConfig = R"(
[gpio]
kill_switch = { line = "KILL_SWITCH" }
kill_output = { line = "KILL_OUT" }
power_off_output = { line = "POWER_OFF" }
scl = { line = "GPIO3" }
sda = { line = "GPIO2" }
)";

std::string config(const std::string& control, const std::string& recovery) {
    return "[control]\n" + control + "\n" + kGpioConfig + "\n[recovery]\n" + recovery + "\n";
}

uint8_t speed_byte(int v) {
    const int steps = (std::abs(v) * 102 + 4425) / 8850;
    if (steps == 0)
        return 0x80;
    return static_cast<uint8_t>(v > 0 ? 0x80 + steps : 0x7F - steps);
}

const std::string kSim = "/org/caracara/Simulator1";
const char* kSimIface = "org.caracara.Simulator1";

bool all_at(SimFixture& f, const std::vector<int32_t>& v) {
    for (unsigned i = 0; i < 8; ++i)
        if (f.thruster_byte(i, "OrderedSpeed") != speed_byte(v[i]))
            return false;
    return true;
}

// Commands `v` and waits until every simulated thruster holds it.
void drive(DaemonFixture& d, SimFixture& f, const std::vector<int32_t>& v) {
    REQUIRE(d.set_thrust(v) == "");
    REQUIRE(d.wait_for([&] { return all_at(f, v); }));
}

uint64_t now_ns() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<uint64_t>(ts.tv_sec) * 1000000000ull + static_cast<uint64_t>(ts.tv_nsec);
}

} // namespace

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
    uint64_t last_zero = 0, power_off_edge = 0;
    for (const auto& e : log) {
        if (e.bus == "i2c" && !e.read && e.result == "ack" && e.data.size() == 3 && e.data[0] == speed_byte(0))
            last_zero = e.index;
        if (e.bus == "gpio" && e.addr == kPowerOffLine && power_off_edge == 0)
            power_off_edge = e.index;
    }
    INFO("last zero order #" << last_zero << ", then line edge #" << power_off_edge);
    CHECK(last_zero > 0);
    CHECK(power_off_edge > last_zero);
    CHECK(d.vehicle_string("State") == "powered-off");
    // Clean exits: a sanitizer report or a crash would show here.
    CHECK(d.daemon.terminate() == 0);
    CHECK(f.sim.terminate() == 0);
}

TEST_CASE("a crashing daemon, or one ended by a stray signal, zeroes the thrusters on its way out") {
    for (int sig : {SIGSEGV, SIGABRT, SIGQUIT, SIGUSR1, SIGALRM}) {
        INFO("signal " << sig);
        SimFixture f;
        DaemonFixture d(f, config("arming_delay_ms = 200\ncommand_timeout_ms = 60000", "enabled = false"));
        const std::vector<int32_t> v = {2000, 2000, 2000, 2000, 2000, 2000, 2000, 2000};
        drive(d, f, v);
        REQUIRE(f.call(kSim, kSimIface, "ClearWireLog", "") == "");
        kill(d.daemon.pid(), sig);
        const int status = d.daemon.wait_exit(10000);
        // Died of that signal, as it would have without the handler (ASan may turn SIGSEGV into
        // an abort).
        if (sig == SIGSEGV)
            CHECK(status > 128);
        else
            CHECK(status == 128 + sig);
        CHECK(all_at(f, std::vector<int32_t>(8, 0)));
        // The handler asserted the kill output before its first zero order (wire-log order).
        uint64_t kill_edge = 0, first_zero = 0;
        for (const auto& e : f.wire_log()) {
            if (e.bus == "gpio" && e.addr == 27 && kill_edge == 0)
                kill_edge = e.index;
            if (e.bus == "i2c" && !e.read && e.data.size() == 3 && e.data[0] == speed_byte(0) && first_zero == 0)
                first_zero = e.index;
        }
        INFO("kill output edge #" << kill_edge << ", first zero order #" << first_zero);
        CHECK(kill_edge > 0);
        CHECK(kill_edge < first_zero);
        CHECK(f.sim.terminate() == 0);
    }
}

TEST_CASE("terminal stop signals do not freeze a daemon that is driving the thrusters") {
    // Ctrl-Z, or a background daemon writing to its terminal, would stop it with the thrusters
    // running and no command timeout able to fire. Only SIGSTOP, which nothing can catch, can.
    SimFixture f;
    DaemonFixture d(f, config("arming_delay_ms = 200\ncommand_timeout_ms = 60000", "enabled = false"));
    const std::vector<int32_t> v = {1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500};
    drive(d, f, v);
    auto stopped = [&] {
        std::ifstream stat("/proc/" + std::to_string(d.daemon.pid()) + "/stat");
        std::string line;
        std::getline(stat, line);
        const auto paren = line.rfind(')');
        return paren != std::string::npos && paren + 2 < line.size() && line[paren + 2] == 'T';
    };
    for (int sig : {SIGTSTP, SIGTTIN, SIGTTOU}) {
        INFO("signal " << sig);
        kill(d.daemon.pid(), sig);
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        CHECK_FALSE(stopped());
        kill(d.daemon.pid(), SIGCONT); // keeps a failure from hanging the calls below
        const uint64_t before = d.bus_u64("Transactions");
        CHECK(d.wait_for([&] { return d.bus_u64("Transactions") > before + 20; }));
    }
    REQUIRE(d.set_thrust(std::vector<int32_t>(8, 0)) == "");
    CHECK(d.wait_for([&] { return all_at(f, std::vector<int32_t>(8, 0)); }));
    CHECK(d.daemon.terminate() == 0);
    CHECK(f.sim.terminate() == 0);
}

TEST_CASE("a daemon that loses its D-Bus connection zeroes the thrusters and exits for a restart") {
    // The daemon on a bus of its own, so that the bus daemon can die under it while the
    // simulator's inspection API stays reachable on the other.
    SimFixture f;
    Process daemon_bus;
    const std::string address = start_private_bus(daemon_bus, f.dir(), "daemon-bus");
    DaemonFixture d(f, config("arming_delay_ms = 200\ncommand_timeout_ms = 60000", "enabled = false"), true, address);
    const std::vector<int32_t> v = {-1800, 1800, -1800, 1800, -1800, 1800, -1800, 1800};
    drive(d, f, v);
    daemon_bus.stop(SIGKILL);
    // A failure exit, so that systemd's Restart=on-failure brings it back.
    CHECK(d.daemon.wait_exit(10000) == 1);
    CHECK(all_at(f, std::vector<int32_t>(8, 0)));
    CHECK_THAT(read_file(f.dir() + "/caracarad.log"), Catch::Contains("lost its connection to the bus"));
    CHECK(f.sim.terminate() == 0);
}
