// daemon/teensy/TeensyPort on the daemon's objects over the fakes of the device seam
// (DaemonRig), the Teensy not fitted: which refusals come at once, before anything is handed to
// the link (LED values out of range, a vehicle that may not move the wheels, powered off), and
// that a command the link cannot carry is answered LinkError through its completion, never
// silently; none of them changes the LEDs or the commanding client.
#include "daemon/teensy/teensy_port.hpp"

#include "tests/catch.hpp"
#include "tests/unit/fakes/daemon_rig.hpp"

#include <optional>

using namespace caracara;
using namespace caracara::test;

namespace {

// `start` and, if it was not refused at once, the result its completion got.
Result outcome(DaemonRig& rig, const std::function<Result(Completion)>& start) {
    std::optional<Result> later;
    const Result now = start([&](const Result& r) { later = r; });
    if (!now.ok())
        return now;
    REQUIRE(rig.run_until([&] { return later.has_value(); }));
    return *later;
}

} // namespace

TEST_CASE("TeensyPort: LED values out of range refused before the link; in range, LinkError when it is not there") {
    DaemonRig rig;
    rig.run_until_ready();
    TeensyPort& t = rig.daemon().teensy();
    CHECK(t.set_leds(256, 0, 0, nullptr).status == Status::OutOfRange);
    CHECK(t.set_leds(0, -1, 0, nullptr).status == Status::OutOfRange);
    const Result r = outcome(rig, [&](Completion done) { return t.set_leds(10, 20, 30, std::move(done)); });
    CHECK(r.status == Status::LinkError);
    CHECK(t.leds() == decltype(t.leds()){0, 0, 0});
}

TEST_CASE("TeensyPort: moving the wheels is refused at once while killed; stopping them is never refused by the state") {
    DaemonRig rig;
    rig.run_until_ready();
    REQUIRE(rig.vehicle().kill(KillSource::DBus, "test").ok());
    TeensyPort& t = rig.daemon().teensy();
    bool completed = false;
    CHECK(t.set_speed(100, -100, ":1.7", [&](const Result&) { completed = true; }).status == Status::Killed);
    CHECK(t.turn(0.5, false, ":1.7", [&](const Result&) { completed = true; }).status == Status::Killed);
    rig.run_for(30);
    CHECK_FALSE(completed); // refused at once: no completion besides
    CHECK(rig.vehicle().readings().controller_client().empty());
    // Stopping goes to the link even when killed; the link is not there.
    CHECK(outcome(rig, [&](Completion done) { return t.set_speed(0, 0, ":1.7", std::move(done)); }).status ==
          Status::LinkError);
    CHECK(outcome(rig, [&](Completion done) { return t.stop(50, std::move(done)); }).status == Status::LinkError);
}

TEST_CASE("TeensyPort: powered off, the LEDs and the servos are refused PoweredOff") {
    DaemonRig rig;
    rig.run_until_ready();
    std::optional<Result> off;
    rig.vehicle().power_off("power-off", [&](const Result& r) { off = r; });
    REQUIRE(rig.run_until([&] { return off.has_value(); }));
    REQUIRE(off->ok());
    TeensyPort& t = rig.daemon().teensy();
    CHECK(t.set_leds(1, 2, 3, nullptr).status == Status::PoweredOff);
    CHECK(t.servo(1, 90, nullptr).status == Status::PoweredOff);
    CHECK(t.set_speed(100, 100, ":1.7", nullptr).status == Status::PoweredOff);
}
