// daemon/teensy/TeensyTurn in a VehicleDaemon on the fakes (DaemonRig) whose SPI node is the
// simulator's own Teensy model (FakeTeensyIo), which turns at its configured rate: a Turn (or
// Turn to) goes to the Teensy, then Confirm until it has turned, and the caller is answered once
// the Teensy's completion is acknowledged; a second turn while one runs, a non-finite angle, or
// a Teensy that is not there are refused at once and nothing reaches it; a kill ends a running
// turn with its error and the Teensy is told Stop.
#include "daemon/teensy/teensy_port.hpp"

#include "core/safety.hpp"
#include "tests/catch.hpp"
#include "tests/unit/fakes/daemon_rig.hpp"
#include "tests/unit/fakes/fake_teensy_io.hpp"

#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>

using namespace caracara;
using namespace caracara::test;
namespace fw = caracara::sim::teensy; // the firmware's command ids

namespace {

// A DaemonRig whose Teensy is the model behind a FakeTeensyIo; no command timeout in the test,
// and a silence of 600 ms (as test_teensy_connection's, for runs under ASan and qemu-user).
struct TurnRig {
    TurnRig() {
        rig = std::make_unique<DaemonRig>("loop_rate_hz = 50\ncommand_timeout_ms = 60000\n", "[spi]\nfitted = true\nsilence_ms = 600\n",
                                          false, &io);
        rig->run_until_ready();
        REQUIRE(rig->run_until([&] { return port().telemetry().online; }));
    }
    ~TurnRig() { rig.reset(); } // the daemon before the node it talks to

    TeensyPort& port() { return rig->daemon().teensy(); }
    uint64_t executed(uint8_t command) { return io.executed(command); }
    sim::TeensyTaskState task() {
        sim::TeensyTaskState s{};
        io.model([&](sim::TeensyModel& m) { s = m.task_state(); });
        return s;
    }

    FakeTeensyIo io{"/dev/spidev0.0"};
    std::unique_ptr<DaemonRig> rig;
};

} // namespace

TEST_CASE("Turn: the Turn frame, Confirm until the Teensy has turned, answered once it is acknowledged") {
    TurnRig t;
    std::optional<Result> done;
    const Result started = t.port().turn(0.25, false, ":1.7", [&](const Result& r) { done = r; });
    REQUIRE(started.ok());
    CHECK(t.port().telemetry().turning);
    CHECK(t.rig->vehicle().readings().controller_client() == ":1.7");
    REQUIRE(t.rig->run_until([&] { return done.has_value(); }));
    CHECK(done->ok());
    CHECK_FALSE(t.port().telemetry().turning);
    CHECK(t.executed(fw::kTurn) == 1);
    CHECK(t.executed(fw::kConfirm) >= 1);
    float last = 0;
    uint64_t acks = 0;
    t.io.model([&](sim::TeensyModel& m) {
        last = m.last_turn_rad();
        acks = m.acknowledgements();
    });
    CHECK(last == Approx(0.25));
    CHECK(acks == 1); // the completion acknowledged, once
    CHECK(t.task() == sim::TeensyTaskState::Idle);

    // Turn to: absolute.
    done.reset();
    REQUIRE(t.port().turn(-0.5, true, ":1.7", [&](const Result& r) { done = r; }).ok());
    REQUIRE(t.rig->run_until([&] { return done.has_value(); }));
    CHECK(done->ok());
    t.io.model([&](sim::TeensyModel& m) { last = m.last_turn_to_rad(); });
    CHECK(last == Approx(-0.5));
    CHECK(t.executed(fw::kTurnTo) == 1);
    CHECK(t.task() == sim::TeensyTaskState::Idle);
}

TEST_CASE("Turn: a second turn while one runs is Busy, a non-finite angle InvalidValue; neither reaches the Teensy") {
    TurnRig t;
    bool nan_done = false;
    CHECK(t.port().turn(std::numeric_limits<double>::quiet_NaN(), false, ":1.7", [&](const Result&) { nan_done = true; })
              .status == Status::InvalidValue);
    CHECK(t.rig->vehicle().readings().controller_client().empty()); // refused: no one commands
    std::optional<Result> first;
    REQUIRE(t.port().turn(2.0, false, ":1.7", [&](const Result& r) { first = r; }).ok());
    REQUIRE(t.rig->run_until([&] { return t.task() == sim::TeensyTaskState::Running; }));
    bool second_done = false;
    CHECK(t.port().turn(0.1, false, ":1.7", [&](const Result&) { second_done = true; }).status == Status::Busy);
    t.rig->run_for(60);
    CHECK(t.executed(fw::kTurn) == 1);
    float last = 0;
    t.io.model([&](sim::TeensyModel& m) { last = m.last_turn_rad(); });
    CHECK(last == Approx(2.0));
    CHECK_FALSE(nan_done);
    CHECK_FALSE(second_done);
    CHECK_FALSE(first.has_value());
    // The first one is still running: it ends with the kill, before `first` goes out of scope.
    REQUIRE(t.rig->vehicle().kill(KillSource::DBus, "test").ok());
    REQUIRE(t.rig->run_until([&] { return first.has_value(); }));
    CHECK_FALSE(second_done);
}

TEST_CASE("Turn: a kill ends a running turn with its error, and the Teensy is told Stop") {
    TurnRig t;
    std::optional<Result> done;
    REQUIRE(t.port().turn(3.0, false, ":1.7", [&](const Result& r) { done = r; }).ok());
    REQUIRE(t.rig->run_until([&] { return t.task() == sim::TeensyTaskState::Running; }));
    const uint64_t stops = t.executed(fw::kStop);
    REQUIRE(t.rig->vehicle().kill(KillSource::DBus, "test").ok());
    REQUIRE(t.rig->run_until([&] { return done.has_value(); }));
    CHECK_FALSE(done->ok());
    CHECK(done->status == Status::Killed);
    CHECK_FALSE(t.port().telemetry().turning);
    REQUIRE(t.rig->run_until([&] { return t.executed(fw::kStop) > stops; }));
    // The Teensy's turn ended where it was, not run to its end.
    double remaining = 1;
    t.io.model([&](sim::TeensyModel& m) { remaining = m.turn_remaining_rad(); });
    CHECK(remaining == 0);
    CHECK(t.task() != sim::TeensyTaskState::Running);
}

TEST_CASE("Turn: with no Teensy there, LinkError at once; no one becomes the commanding client") {
    DaemonRig rig; // not fitted, and absent: no failsafe, the vehicle ready
    rig.run_until_ready();
    bool completed = false;
    const Result r = rig.daemon().teensy().turn(0.5, false, ":1.7", [&](const Result&) { completed = true; });
    CHECK(r.status == Status::LinkError);
    CHECK(rig.vehicle().readings().controller_client().empty());
    rig.run_for(60);
    CHECK_FALSE(completed);
    CHECK_FALSE(rig.daemon().teensy().telemetry().turning);
}
