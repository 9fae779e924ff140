// daemon/recovery/BusLoss on a VehicleDaemon on the fakes (DaemonRig): a slave on the fake wire
// holds SDA or SCL low, so every transfer times out. Without [recovery] a locked bus is lost at
// once: killed by the bus (the kill output first), bus-lost held, ClearKill refused; once a
// transfer gets through, bus-lost clears, the zeros reach every thruster, and the vehicle stays
// killed until ClearKill. With [recovery], a lockup that outlasts the command timeout is a lost
// bus, though attempts remain; one cleared within it is no loss.
#include "tests/unit/fakes/daemon_rig.hpp"

#include "core/clock.hpp"
#include "core/safety.hpp"
#include "tests/catch.hpp"

#include <string>
#include <vector>

using namespace caracara;
using namespace caracara::test;
using Kind = WireEvent::Kind;

namespace {

const std::vector<int32_t> kDrive{2000, -2000, 3000, -3000, 1000, -1000, 4000, -4000};
constexpr uint32_t kCommandTimeoutMs = 300;

BusTelemetry& bus(DaemonRig& rig) { return rig.daemon().bus().monitor().telemetry(); }
SafetyState state(DaemonRig& rig) { return rig.vehicle().readings().safety().state(); }

// Ready, with kDrive on the wire.
void drive(DaemonRig& rig) {
    rig.run_until_ready();
    REQUIRE(rig.vehicle().motors().set_thrust(kDrive, ":1.7").ok());
    REQUIRE(rig.run_until([&] { return each_ordered(rig.wire().events(), kDrive); }));
}

bool bus_lost_holds(DaemonRig& rig) {
    const auto& active = rig.daemon().failsafes().active();
    return active.size() == 1 && active[0].condition == FailsafeCondition::BusLost;
}

} // namespace

TEST_CASE("without recovery a locked bus is lost at once: killed by the bus, kill output first; back, the zeros go out and the kill stays") {
    DaemonRig rig("loop_rate_hz = 50\ncommand_timeout_ms = 60000\n");
    drive(rig);
    rig.wire().clear();
    rig.wire().hold_sda(1); // no bus clear without [recovery]: held until the test lets go
    REQUIRE(rig.run_until([&] { return bus(rig).state == BusState::Lost; }));
    CHECK(state(rig) == SafetyState::Killed);
    CHECK(rig.vehicle().readings().kill_source_name() == "bus");
    CHECK(rig.vehicle().readings().safety().kill_record().reason.find("I2C bus lost") != std::string::npos);
    CHECK(kill_output(rig.wire().events(), 1) >= 0);
    CHECK(bus_lost_holds(rig));
    CHECK_FALSE(rig.vehicle().clear_kill().ok());
    rig.run_for(100); // more cycles on the lost bus: it is lost once, killed once
    CHECK(bus_lost_holds(rig));

    rig.wire().hold_sda(0);
    REQUIRE(rig.run_until([&] { return bus(rig).state == BusState::Ok; }));
    REQUIRE(rig.run_until([&] { return rig.daemon().failsafes().active().empty(); }));
    REQUIRE(rig.run_until([&] { return all_zeroed(rig.wire().events()); }));
    CHECK(find(rig.wire().events(), [](const WireEvent& e) { return e.kind == Kind::Order && e.value != 0; }) < 0);
    CHECK(state(rig) == SafetyState::Killed); // the bus back does not clear the kill
    CHECK(rig.vehicle().clear_kill().ok());
    REQUIRE(rig.run_until([&] { return rig.vehicle().readings().may_drive(); }));
    REQUIRE(rig.vehicle().motors().set_thrust(kDrive, ":1.7").ok());
    REQUIRE(rig.run_until([&] { return each_ordered(rig.wire().events(), kDrive); }));
}

TEST_CASE("a lockup under recovery that outlasts the command timeout is a lost bus, though attempts remain") {
    const std::string control = "loop_rate_hz = 50\ncommand_timeout_ms = " + std::to_string(kCommandTimeoutMs) + "\n";
    // Attempts that outlast the command timeout many times over (50, 100, 200, ... ms apart).
    DaemonRig rig(control, "[recovery]\nenabled = true\nattempts = 10\nbackoff_ms = 50\n");
    rig.run_until_ready();
    rig.wire().clear();
    const uint64_t held_at = monotonic_ns();
    rig.wire().hold_scl(true);
    REQUIRE(rig.run_until([&] { return state(rig) == SafetyState::Killed; }));
    // No sooner than the command timeout after the hold (the lockup is found after it).
    CHECK(monotonic_ns() - held_at >= ms_to_ns(kCommandTimeoutMs));
    CHECK(bus(rig).state == BusState::Lost);
    CHECK(rig.vehicle().readings().kill_source_name() == "bus");
    const std::string why = "locked up for longer than the command timeout (" + std::to_string(kCommandTimeoutMs) + " ms)";
    CHECK(rig.vehicle().readings().safety().kill_record().reason.find(why) != std::string::npos);
    CHECK(bus(rig).last_recovery_error == why);
    CHECK(bus_lost_holds(rig));
    CHECK(kill_output(rig.wire().events(), 1) >= 0);
    // Recovery goes on: let go, the next attempt clears the bus and bus-lost with it.
    rig.wire().hold_scl(false);
    REQUIRE(rig.run_until([&] { return bus(rig).state == BusState::Ok; }));
    REQUIRE(rig.run_until([&] { return rig.daemon().failsafes().active().empty(); }));
    CHECK(state(rig) == SafetyState::Killed);
}

TEST_CASE("a lockup cleared within the command timeout is no loss: no kill, no bus-lost") {
    const std::string control = "loop_rate_hz = 50\ncommand_timeout_ms = " + std::to_string(kCommandTimeoutMs) + "\n";
    DaemonRig rig(control, "[recovery]\nenabled = true\nattempts = 3\nbackoff_ms = 50\n");
    rig.run_until_ready();
    rig.wire().clear();
    rig.wire().hold_sda(3);
    REQUIRE(rig.run_until([&] { return bus(rig).recoveries == 1; }));
    // Past the command timeout since the lockup: its timer does not kill a bus that is back.
    rig.run_for(static_cast<int>(2 * kCommandTimeoutMs));
    CHECK(bus(rig).state == BusState::Ok);
    CHECK(state(rig) == SafetyState::Ready);
    CHECK(rig.daemon().failsafes().active().empty());
    CHECK(kill_output(rig.wire().events(), 1) < 0);
}
