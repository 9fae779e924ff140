// daemon/teensy/TeensyConnection with its TeensyPoll, TeensyLinkWatch and TeensyReopen, in a
// VehicleDaemon on the fakes (DaemonRig) whose SPI node is the simulator's own Teensy model
// (FakeTeensyIo): judged by what the Teensy got (its frame log, its wheels and LEDs), what the
// daemon read from it (the telemetry), the failsafes and the fake I2C wire (the kill output, the
// thrusters' zeros). The poll reads the three axes and the distance sensors in turn; a Teensy
// that falls silent (no answer, a garbage ack, busy for ever, a frame held) or whose node goes
// away kills by teensy-link-lost, and is back (the wheels stopped, the failsafe cleared, the kill
// kept) at its next valid frame; a node that went, or a fitted Teensy absent at start, is asked
// for again until it opens; a Teensy not fitted is relied on once it has answered.
#include "daemon/teensy/teensy_port.hpp"

#include "core/safety.hpp"
#include "tests/catch.hpp"
#include "tests/unit/fakes/daemon_rig.hpp"
#include "tests/unit/fakes/fake_teensy_io.hpp"

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

using namespace caracara;
using namespace caracara::test;
namespace fw = caracara::sim::teensy; // the firmware's command ids

namespace {

const std::vector<int32_t> kDrive{1000, -2000, 3000, -4000, 500, -500, 1500, -1500};
const char* const kDevice = "/dev/spidev0.0";

// A DaemonRig whose Teensy is the model behind a FakeTeensyIo (there, or gone at start). Its
// silence_ms is 600, not the default 200: these tests run on the wall clock, also under ASan and
// qemu-user (arm64), where a stalled poll must not read as a Teensy falling silent.
struct TeensyRig {
    explicit TeensyRig(const std::string& spi = "[spi]\nfitted = true\nsilence_ms = 600\n", bool absent = false) {
        io.set_gone(absent);
        rig = std::make_unique<DaemonRig>("loop_rate_hz = 50\ncommand_timeout_ms = 60000\n", spi, false, &io);
    }
    ~TeensyRig() { rig.reset(); } // the daemon before the node it talks to

    TeensyPort& port() { return rig->daemon().teensy(); }
    uint64_t executed(uint8_t command) { return io.executed(command); }
    uint64_t received(uint8_t command) { return io.received(command); }
    uint64_t frames() { return io.frames(); }
    SafetyState state() { return rig->vehicle().readings().safety().state(); }
    bool link_lost_holds() {
        const auto& a = rig->daemon().failsafes().active();
        return a.size() == 1 && a[0].condition == FailsafeCondition::TeensyLinkLost;
    }
    // Ready, with kDrive on the I2C wire, the Teensy answering.
    void drive() {
        rig->run_until_ready();
        REQUIRE(rig->run_until([&] { return port().telemetry().online; }));
        REQUIRE(rig->vehicle().motors().set_thrust(kDrive, ":1.7").ok());
        REQUIRE(rig->run_until([&] { return each_ordered(rig->wire().events(), kDrive); }));
        rig->wire().clear();
    }
    // Killed by teensy-link-lost for `why`: the kill output, then every thruster's zero.
    void check_killed(TeensyLoss why) {
        REQUIRE(rig->run_until([&] { return state() == SafetyState::Killed; }));
        CHECK(port().loss() == why);
        CHECK(port().link_lost());
        CHECK_FALSE(port().telemetry().online);
        CHECK(link_lost_holds());
        CHECK(rig->vehicle().readings().safety().kill_record().reason == "teensy-link-lost kill");
        REQUIRE(rig->run_until([&] {
            const auto ev = rig->wire().events();
            const long at = kill_output(ev, 1);
            return at >= 0 && all_zeroed(ev, at);
        }));
        const Result r = rig->vehicle().clear_kill();
        CHECK(r.status == Status::FailsafeActive);
        CHECK(r.message.find("teensy-link-lost") != std::string::npos);
    }
    // Back at its next valid frame: the wheels stopped (a Stop more than `stops`), the failsafe
    // cleared, the vehicle still killed until ClearKill.
    void check_back(uint64_t stops) {
        REQUIRE(rig->run_until([&] { return !port().link_lost() && rig->daemon().failsafes().active().empty(); }));
        CHECK(port().loss() == TeensyLoss::None);
        CHECK(port().telemetry().online);
        REQUIRE(rig->run_until([&] { return executed(fw::kStop) > stops; }));
        CHECK(state() == SafetyState::Killed);
        CHECK(rig->vehicle().clear_kill().ok());
    }

    FakeTeensyIo io{kDevice};
    std::unique_ptr<DaemonRig> rig;
};

// `start` and the result its completion got (it must not be refused at once).
Result completed(DaemonRig& rig, const std::function<Result(Completion)>& start) {
    std::optional<Result> later;
    const Result now = start([&](const Result& r) { later = r; });
    REQUIRE(now.ok());
    REQUIRE(rig.run_until([&] { return later.has_value(); }));
    return *later;
}

} // namespace

TEST_CASE("TeensyPoll: the three axes and every distance sensor are read in turn into the telemetry; no failsafe") {
    TeensyRig t;
    t.io.set_attitude({0.5, 0.125, -0.25});
    t.io.model([](sim::TeensyModel& m) {
        for (std::size_t i = 0; i < 4; ++i)
            REQUIRE(m.set_distance_mm(i, static_cast<uint16_t>(100 * (i + 1))));
    });
    t.rig->run_until_ready();
    const TeensyTelemetry& tm = t.port().telemetry();
    REQUIRE(t.rig->run_until([&] {
        return tm.distances == std::vector<uint16_t>{100, 200, 300, 400} && tm.orientation[0] == Approx(0.5) &&
               tm.orientation[1] == Approx(0.125) && tm.orientation[2] == Approx(-0.25);
    }));
    CHECK(tm.online);
    CHECK(tm.orientation_read_ns != 0);
    CHECK(t.executed(fw::kGetOrientation) >= 3);
    CHECK(t.executed(fw::kGetDistance) >= 4);
    CHECK_FALSE(t.port().link_lost());
    CHECK(t.rig->daemon().failsafes().active().empty());
    CHECK(t.state() == SafetyState::Ready);
    // A changed reading follows.
    t.io.set_attitude({-1.0, 0, 0});
    REQUIRE(t.rig->run_until([&] { return tm.orientation[0] == Approx(-1.0); }));
}

TEST_CASE("TeensyLinkWatch: a Teensy that falls silent kills by teensy-link-lost; its next valid frame clears it") {
    // Each way of falling silent: nothing answers, the ack is garbage, busy for ever.
    const std::vector<std::pair<const char*, std::function<void(sim::TeensyFaults&)>>> silences{
        {"no answer", [](sim::TeensyFaults& f) { f.inject_no_answer(1'000'000); }},
        {"garbage ack", [](sim::TeensyFaults& f) { f.inject_garbage_ack(1'000'000); }},
        {"busy", [](sim::TeensyFaults& f) { f.inject_busy(1'000'000); }},
    };
    for (const auto& [name, fault] : silences) {
        INFO(name);
        TeensyRig t;
        t.drive();
        const uint64_t asked = t.received(fw::kStop);
        t.io.model([&](sim::TeensyModel& m) { fault(m.faults()); });
        t.check_killed(TeensyLoss::Silent);
        // The kill's own Stop reached the silent Teensy and is over (its resends too) before it
        // answers again: a Stop after this is the one of its coming back.
        REQUIRE(t.rig->run_until([&] { return t.received(fw::kStop) > asked; }));
        t.rig->run_for(100);
        const uint64_t stops = t.executed(fw::kStop);
        t.io.model([](sim::TeensyModel& m) { m.faults().clear(); });
        t.check_back(stops);
    }
}

TEST_CASE("TeensyLinkWatch: a frame held on the wire (a hung Teensy) is silence: the kill goes out meanwhile, not behind it") {
    TeensyRig t;
    t.drive();
    t.io.hold(true);
    // The kill output and the zeros reach the I2C wire while the Teensy's frame is still held.
    t.check_killed(TeensyLoss::Silent);
    const uint64_t stops = t.executed(fw::kStop);
    t.io.hold(false);
    t.check_back(stops);
}

TEST_CASE("TeensyConnection: the node gone kills at once; TeensyReopen asks again until it is back, the wheels stopped") {
    TeensyRig t;
    t.drive();
    t.io.set_gone(true);
    t.check_killed(TeensyLoss::Gone);
    CHECK_FALSE(t.port().is_open());
    // Nothing reaches a node that is not there, and nothing is lost twice: past the first ask
    // again (a second after the loss), still gone, so it is asked for once more.
    const uint64_t frames = t.frames();
    t.rig->run_for(1200);
    CHECK(t.frames() == frames);
    CHECK(t.port().loss() == TeensyLoss::Gone);
    const uint64_t stops = t.executed(fw::kStop);
    t.io.set_gone(false);
    // A give-up time, not a bound: asked for again once a second.
    REQUIRE(t.rig->run_until([&] { return t.port().is_open(); }));
    t.check_back(stops);
}

TEST_CASE("TeensyConnection: a fitted Teensy absent at start keeps the vehicle killed; picked up once it comes") {
    TeensyRig t("[spi]\nfitted = true\nsilence_ms = 600\n", true);
    t.rig->run_for(60);
    CHECK(t.state() == SafetyState::Killed);
    CHECK(t.port().loss() == TeensyLoss::Absent);
    CHECK(t.link_lost_holds());
    CHECK(t.frames() == 0);
    t.io.set_gone(false);
    REQUIRE(t.rig->run_until([&] { return t.rig->daemon().failsafes().active().empty(); }));
    CHECK(t.port().telemetry().online);
    CHECK(t.executed(fw::kStop) >= 1); // the wheels stopped, as at every start
    CHECK(t.rig->vehicle().clear_kill().ok());
}

TEST_CASE("TeensyLinkWatch: a Teensy not fitted is relied on once it has answered: its silence kills") {
    TeensyRig t("[spi]\nfitted = false\nsilence_ms = 600\n");
    t.drive();
    t.io.model([](sim::TeensyModel& m) { m.faults().inject_no_answer(1'000'000); });
    t.check_killed(TeensyLoss::Silent);
}

TEST_CASE("TeensyConnection: a command's frame reaches the Teensy and its result comes back; gone, LinkError") {
    TeensyRig t;
    t.drive();
    TeensyPort& p = t.port();
    CHECK(completed(*t.rig, [&](Completion done) { return p.set_leds(10, 20, 30, std::move(done)); }).ok());
    std::array<uint8_t, 3> leds{};
    t.io.model([&](sim::TeensyModel& m) { leds = m.leds(); });
    CHECK(leds == std::array<uint8_t, 3>{10, 20, 30});
    CHECK(p.leds() == std::array<uint8_t, 3>{10, 20, 30});
    CHECK(completed(*t.rig, [&](Completion done) { return p.set_speed(40, -40, ":1.7", std::move(done)); }).ok());
    sim::TeensyWheels wheels;
    t.io.model([&](sim::TeensyModel& m) { wheels = m.wheels(); });
    CHECK(wheels.front_left == 40);
    CHECK(wheels.front_right == -40);

    // The node goes under a command: LinkError through its completion, and the link is lost.
    t.io.set_gone(true);
    const Result r = completed(*t.rig, [&](Completion done) { return p.set_leds(1, 2, 3, std::move(done)); });
    CHECK(r.status == Status::LinkError);
    CHECK(p.leds() == std::array<uint8_t, 3>{10, 20, 30});
    t.check_killed(TeensyLoss::Gone);
    // Closed now: refused at once, before the link.
    CHECK(p.set_leds(1, 2, 3, nullptr).status == Status::LinkError);
}
