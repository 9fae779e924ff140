// The ways a running caracarad ends without a clean stop (a crash, a stray fatal signal, a
// terminal stop signal, a lost D-Bus connection): the thrusters end at zero, checked on the
// simulator's side of the wire.
#include "tests/integration/daemon_on_sim.hpp"

#include <csignal>
#include <chrono>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

using namespace caracara::test;

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
