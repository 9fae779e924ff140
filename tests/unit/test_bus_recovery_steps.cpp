// daemon/recovery/BusRecovery and its BusRecoverySteps on a VehicleDaemon on the fakes
// (DaemonRig), [recovery] enabled: a slave on the fake wire holds SDA (or SCL) low, so every
// transfer times out. Judged by the fake wire, as the integration test judges caracarad on the
// simulator: the bus clear's clock pulses and its STOP, then every thruster's order again; the
// pulses the clear needed; SCL held low cannot be clocked free (the bus lost, the vehicle killed
// by the bus, back once it answers); a kill during the recovery reaches every thruster first.
#include "tests/unit/fakes/daemon_rig.hpp"

#include "core/clock.hpp"
#include "core/recovery_policy.hpp"
#include "core/safety.hpp"
#include "tests/catch.hpp"

#include <string>
#include <vector>

using namespace caracara;
using namespace caracara::test;
using Kind = WireEvent::Kind;

namespace {

const std::vector<int32_t> kDrive{2000, -2000, 3000, -3000, 1000, -1000, 4000, -4000};
// Orders that stand for the whole test (no command timeout).
const char* const kControl = "loop_rate_hz = 50\ncommand_timeout_ms = 60000\n";
// No rebind: the fakes have no sysfs (the bus clear itself is what is judged).
const char* const kRecovery = "[recovery]\nenabled = true\nattempts = 2\nbackoff_ms = 50\n";

BusTelemetry& bus(DaemonRig& rig) { return rig.daemon().bus().monitor().telemetry(); }

void drive(DaemonRig& rig) {
    rig.run_until_ready();
    REQUIRE(rig.vehicle().motors().set_thrust(kDrive, ":1.7").ok());
    REQUIRE(rig.run_until([&] { return each_ordered(rig.wire().events(), kDrive); }));
}

long stop_at(const std::vector<WireEvent>& ev) {
    return find(ev, [](const WireEvent& e) { return e.kind == Kind::Stop; });
}

long pulses_before(const std::vector<WireEvent>& ev, long end) {
    long n = 0;
    for (long i = 0; i < end; ++i)
        n += ev[static_cast<std::size_t>(i)].kind == Kind::SclPulse;
    return n;
}

} // namespace

TEST_CASE("a slave holding SDA for k pulses: cleared with k pulses and a STOP, every order re-sent, no kill") {
    DaemonRig rig(kControl, kRecovery);
    drive(rig);
    for (unsigned k : {1u, 4u, 9u}) {
        INFO("k = " << k);
        const uint64_t recoveries = bus(rig).recoveries;
        rig.wire().clear();
        rig.wire().hold_sda(k);
        REQUIRE(rig.run_until([&] { return bus(rig).recoveries == recoveries + 1; }));
        const auto ev = rig.wire().events();
        const long stop = stop_at(ev);
        REQUIRE(stop >= 0);
        CHECK(pulses_before(ev, stop) == static_cast<long>(k) + 1); // k clocks, then SCL up for the STOP
        CHECK(each_ordered(ev, kDrive, stop));
        CHECK(bus(rig).last_pulses == k);
        CHECK(bus(rig).state == BusState::Ok);
        CHECK(rig.vehicle().readings().safety().state() == SafetyState::Ready);
        CHECK(kill_output(ev, 1) < 0);
        CHECK(rig.daemon().failsafes().active().empty());
    }
}

TEST_CASE("SCL held low cannot be clocked free: the attempts used up, the bus is lost and kills; back once it answers, killed until ClearKill") {
    DaemonRig rig(kControl, kRecovery);
    drive(rig);
    rig.wire().clear();
    rig.wire().hold_scl(true);
    REQUIRE(rig.run_until([&] { return bus(rig).state == BusState::Lost; }));
    CHECK(bus(rig).recovery_failures >= 2);
    CHECK(bus(rig).last_recovery_error.find("SCL") != std::string::npos);
    CHECK(rig.vehicle().readings().safety().state() == SafetyState::Killed);
    CHECK(rig.vehicle().readings().kill_source_name() == "bus");
    CHECK(kill_output(rig.wire().events(), 1) >= 0);
    CHECK(stop_at(rig.wire().events()) < 0); // no STOP on a clock held low
    REQUIRE(rig.daemon().failsafes().active().size() == 1);
    CHECK(rig.daemon().failsafes().active()[0].condition == FailsafeCondition::BusLost);
    CHECK_FALSE(rig.vehicle().clear_kill().ok());

    // Let go: the background retry clears it, and the zeros of the kill reach every thruster.
    rig.wire().clear();
    rig.wire().hold_scl(false);
    // A give-up time, not a bound: the retry comes RecoveryPolicy::kBackgroundRetryNs after the last.
    const int give_up_ms = static_cast<int>(RecoveryPolicy::kBackgroundRetryNs / 1'000'000) + 3000;
    REQUIRE(rig.run_until([&] { return bus(rig).state == BusState::Ok; }, give_up_ms));
    REQUIRE(rig.run_until([&] { return rig.daemon().failsafes().active().empty(); }));
    REQUIRE(rig.run_until([&] { return all_zeroed(rig.wire().events()); }));
    CHECK(find(rig.wire().events(), [](const WireEvent& e) { return e.kind == Kind::Order && e.value != 0; }) < 0);
    CHECK(rig.vehicle().readings().safety().state() == SafetyState::Killed);
    CHECK(rig.vehicle().clear_kill().ok());
}

TEST_CASE("a kill during the recovery: the kill output at once, and the zeros reach every thruster first once the bus is back") {
    DaemonRig rig(kControl, "[recovery]\nenabled = true\nattempts = 10\nbackoff_ms = 50\n");
    drive(rig);
    rig.wire().clear();
    rig.wire().hold_scl(true);
    REQUIRE(rig.run_until([&] { return bus(rig).recovery_failures >= 1; }));
    REQUIRE(rig.vehicle().kill(KillSource::DBus, "test").ok());
    CHECK(kill_output(rig.wire().events(), 1) >= 0); // not behind the locked bus
    rig.wire().hold_scl(false);
    REQUIRE(rig.run_until([&] { return bus(rig).state == BusState::Ok && bus(rig).recoveries == 1; }));
    REQUIRE(rig.run_until([&] { return all_zeroed(rig.wire().events()); }));
    const auto ev = rig.wire().events();
    const long stop = stop_at(ev);
    REQUIRE(stop >= 0);
    CHECK(all_zeroed(ev, stop));
    CHECK(find(ev, [](const WireEvent& e) { return e.kind == Kind::Order && e.value != 0; }, stop) < 0);
    CHECK(rig.vehicle().readings().kill_source_name() == "dbus");
}
