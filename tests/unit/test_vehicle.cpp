// Vehicle on the in-process fakes of the device seam: each command judged by what reaches the
// fake wire (orders with their motor values, the kill and power-off outputs), in order.
#include "tests/unit/fakes/daemon_rig.hpp"

#include "core/clock.hpp"
#include "core/packet.hpp"
#include "tests/catch.hpp"

#include <algorithm>
#include <optional>
#include <vector>

using namespace caracara;
using namespace caracara::test;
using Kind = WireEvent::Kind;

namespace {

const std::vector<int32_t> kThrust{1000, -2000, 3000, -4000, 500, -500, 1500, -1500};

long first_nonzero_order(const std::vector<WireEvent>& ev, long from = 0) {
    return find(ev, [](const WireEvent& e) { return e.kind == Kind::Order && e.value != 0; }, from);
}

// The kill output was asserted, then every thruster got its zero; after the kill output at most
// one order carries an older value (the transfer already on the wire when the kill came).
// Returns where the kill output is.
long check_kill_output_first(const std::vector<WireEvent>& ev) {
    const long asserted = kill_output(ev, 1);
    REQUIRE(asserted >= 0);
    CHECK(all_zeroed(ev, asserted));
    if (const long stale = first_nonzero_order(ev, asserted); stale >= 0)
        CHECK(first_nonzero_order(ev, stale + 1) < 0);
    return asserted;
}

// Ready, with kThrust on the wire.
void drive(DaemonRig& rig) {
    rig.run_until_ready();
    REQUIRE(rig.vehicle().motors().set_thrust(kThrust, ":1.7").ok());
    REQUIRE(rig.run_until([&] { return each_ordered(rig.wire().events(), kThrust); }));
}

} // namespace

TEST_CASE("SetThrust: each motor value reaches its thruster, and the tick keeps it there") {
    DaemonRig rig;
    rig.run_until_ready();
    rig.wire().clear();
    REQUIRE(rig.vehicle().motors().set_thrust(kThrust, ":1.7").ok());
    REQUIRE(rig.run_until([&] { return each_ordered(rig.wire().events(), kThrust); }));
    // The ticks refresh each order with the same value (three times here)...
    const auto orders_of = [&](const std::vector<WireEvent>& ev, std::size_t i) {
        return std::count_if(ev.begin(), ev.end(), [&](const WireEvent& e) { return e.is_order(i, on_wire(kThrust[i])); });
    };
    REQUIRE(rig.run_until([&] {
        const auto ev = rig.wire().events();
        for (std::size_t i = 0; i < kThrust.size(); ++i)
            if (orders_of(ev, i) < 3)
                return false;
        return true;
    }));
    // ... and once a thruster has its value, it is never ordered anything else.
    const auto ev = rig.wire().events();
    for (std::size_t i = 0; i < kThrust.size(); ++i) {
        const long first = find(ev, [&](const WireEvent& e) { return e.is_order(i, on_wire(kThrust[i])); });
        CHECK(find(ev, [&](const WireEvent& e) { return e.kind == Kind::Order && e.thruster == i && e.value != on_wire(kThrust[i]); },
                   first) < 0);
    }
}

TEST_CASE("a refused command changes nothing on the wire") {
    DaemonRig rig;
    rig.run_until_ready();
    rig.wire().clear();
    std::vector<int32_t> bad = kThrust;
    bad[3] = 9000;
    CHECK(rig.vehicle().motors().set_thrust(bad, ":1.7").status == Status::OutOfRange);
    CHECK(rig.vehicle().motors().set_thrust(std::vector<int32_t>(7, 100), ":1.7").status == Status::InvalidLength);
    rig.run_for(100);
    CHECK(first_nonzero_order(rig.wire().events()) < 0);
}

TEST_CASE("Kill: the kill output first, then a zero to every thruster; the completion after the zeros") {
    DaemonRig rig;
    drive(rig);
    rig.wire().clear();
    std::optional<std::vector<WireEvent>> at_completion;
    rig.vehicle().kill(KillSource::DBus, "test", [&](const Result& r) {
        CHECK(r.ok());
        at_completion = rig.wire().events();
    });
    REQUIRE(rig.run_until([&] { return at_completion.has_value(); }));
    const auto ev = rig.wire().events();
    const long asserted = check_kill_output_first(ev);
    CHECK(all_zeroed(*at_completion, asserted)); // the reply waits for the zeros
    CHECK(rig.vehicle().readings().safety().state() == SafetyState::Killed);
}

TEST_CASE("a Kill behind a hung transfer: the kill output at once, no older order after it") {
    DaemonRig rig;
    drive(rig);
    rig.wire().hold();
    REQUIRE(rig.run_until([&] { return rig.wire().transfer_waiting(); }));
    // Orders queued behind the hung transfer, then the kill.
    REQUIRE(rig.vehicle().motors().set_thrust(std::vector<int32_t>(8, 4000), ":1.7").ok());
    rig.run_for(20);
    rig.wire().clear();
    bool completed = false;
    rig.vehicle().kill(KillSource::DBus, "test", [&](const Result&) { completed = true; });
    CHECK(kill_output(rig.wire().events(), 1) == 0); // not behind the bus
    CHECK_FALSE(completed);
    rig.wire().release();
    REQUIRE(rig.run_until([&] { return completed; }));
    const auto ev = rig.wire().events();
    CHECK(all_zeroed(ev));
    // At most the transfer already on the wire went out with its old value.
    const long stale = first_nonzero_order(ev);
    if (stale >= 0)
        CHECK(first_nonzero_order(ev, stale + 1) < 0);
    CHECK(find(ev, [](const WireEvent& e) { return e.kind == Kind::Order && e.value == on_wire(4000); }) < 0);
}

TEST_CASE("the kill switch: the kill output first, then the zeros; released, the kill stays") {
    DaemonRig rig;
    drive(rig);
    rig.wire().clear();
    rig.gpio().set_kill_switch(true);
    REQUIRE(rig.run_until([&] { return all_zeroed(rig.wire().events()); }));
    check_kill_output_first(rig.wire().events());
    rig.gpio().set_kill_switch(false);
    rig.run_for(60);
    CHECK(rig.vehicle().readings().safety().state() == SafetyState::Killed);
    CHECK(kill_output(rig.wire().events(), 0) < 0);
}

TEST_CASE("started killed with the kill switch set: the kill is the switch's, not the start's") {
    DaemonRig rig("arm_at_start = false\nloop_rate_hz = 50\n", "", true);
    rig.run_for(40);
    REQUIRE(rig.vehicle().readings().safety().state() == SafetyState::Killed);
    // What holds the vehicle killed is the switch, which the user must release.
    CHECK(rig.vehicle().readings().kill_source_name() == "switch");
    CHECK(rig.vehicle().clear_kill().status == Status::KillSwitchSet);
    CHECK(kill_output(rig.wire().events(), 0) < 0);
    rig.gpio().set_kill_switch(false);
    rig.run_for(40);
    CHECK(rig.vehicle().readings().kill_source_name() == "switch"); // released, the kill stays until ClearKill
    CHECK(rig.vehicle().clear_kill().ok());
}

TEST_CASE("a client that leaves: what it sent reaches the wire, then its zeros; the kill only after pilot-lost's persistence") {
    DaemonRig rig("loop_rate_hz = 50\n", "[failsafe.pilot-lost]\npersistence_ms = 300\n");
    rig.run_until_ready();
    rig.wire().clear();
    REQUIRE(rig.vehicle().motors().set_thrust(kThrust, ":1.7").ok());
    const uint64_t left_at = monotonic_ns();
    rig.vehicle().client_left(":1.7"); // before the loop ran: the orders are still due
    // Each thruster gets what the client sent, then its zero.
    const auto sent_then_zero = [&] {
        const auto ev = rig.wire().events();
        for (std::size_t i = 0; i < kThrust.size(); ++i) {
            const long sent = find(ev, [&](const WireEvent& e) { return e.is_order(i, on_wire(kThrust[i])); });
            if (sent < 0 || find(ev, [&](const WireEvent& e) { return e.is_order(i, 0); }, sent) < 0)
                return false;
        }
        return true;
    };
    CHECK(rig.run_until(sent_then_zero));
    CHECK(kill_output(rig.wire().events(), 1) < 0);
    CHECK(rig.vehicle().readings().safety().state() == SafetyState::Ready);
    CHECK(rig.vehicle().readings().controller_client().empty());
    // It was the last pilot: the pilot-lost failsafe kills once its persistence has passed.
    REQUIRE(rig.run_until([&] { return kill_output(rig.wire().events(), 1) >= 0; }, 2000));
    CHECK(monotonic_ns() - left_at >= ms_to_ns(300));
    REQUIRE(rig.run_until([&] { return all_zeroed(rig.wire().events(), kill_output(rig.wire().events(), 1)); }));
    CHECK(rig.vehicle().readings().kill_source_name() == "failsafe");
    CHECK(rig.daemon().failsafes().active().size() == 1);
    check_kill_output_first(rig.wire().events());
    // The kill ended it: a plain ClearKill arms again.
    rig.run_for(100);
    CHECK(rig.daemon().failsafes().active().empty());
    CHECK(rig.vehicle().clear_kill().ok());
}

TEST_CASE("a client that never commanded leaving is no pilot lost") {
    DaemonRig rig("loop_rate_hz = 50\n", "[failsafe.pilot-lost]\npersistence_ms = 100\n");
    rig.run_until_ready();
    rig.vehicle().client_left(":1.5");
    rig.run_for(300);
    CHECK(kill_output(rig.wire().events(), 1) < 0);
    CHECK(rig.vehicle().readings().safety().state() == SafetyState::Ready);
}

TEST_CASE("another client leaving changes nothing") {
    DaemonRig rig;
    rig.run_until_ready();
    REQUIRE(rig.vehicle().motors().set_thrust(kThrust, ":1.7").ok());
    rig.vehicle().client_left(":1.8");
    rig.run_for(60);
    const auto ev = rig.wire().events();
    CHECK(each_ordered(ev, kThrust));
    CHECK(rig.vehicle().readings().motor_values()[0] == 1000);
}

TEST_CASE("the command timeout: zeros, no kill") {
    DaemonRig rig("loop_rate_hz = 50\ncommand_timeout_ms = 100\n");
    drive(rig);
    rig.wire().clear();
    REQUIRE(rig.run_until([&] { return all_zeroed(rig.wire().events()); }, 1000));
    CHECK(kill_output(rig.wire().events(), 1) < 0);
    CHECK(rig.vehicle().readings().safety().state() == SafetyState::Ready);
}

TEST_CASE("PowerOff: the zeros, then the power-off line; the completion after the zeros") {
    DaemonRig rig;
    drive(rig);
    rig.wire().clear();
    std::optional<std::vector<WireEvent>> at_completion;
    rig.vehicle().power_off("power-off", [&](const Result& r) {
        CHECK(r.ok());
        at_completion = rig.wire().events();
    });
    REQUIRE(rig.run_until([&] { return at_completion.has_value(); }));
    CHECK(all_zeroed(*at_completion));
    const auto ev = rig.wire().events();
    const long line = find(ev, [](const WireEvent& e) { return e.kind == Kind::PowerOff && e.value == 1; });
    REQUIRE(line >= 0);
    const long asserted = check_kill_output_first(ev);
    CHECK(asserted < line);
    for (std::size_t i = 0; i < 8; ++i)
        CHECK(find(ev, [&](const WireEvent& e) { return e.is_order(i, 0); }, asserted) < line);
}

TEST_CASE("PowerOff without its confirmation changes nothing") {
    DaemonRig rig;
    rig.run_until_ready();
    std::optional<Result> result;
    rig.vehicle().power_off("yes", [&](const Result& r) { result = r; });
    REQUIRE(rig.run_until([&] { return result.has_value(); }));
    CHECK(result->status == Status::ConfirmationRequired);
    rig.run_for(40);
    CHECK(find(rig.wire().events(), [](const WireEvent& e) { return e.kind == Kind::PowerOff && e.value == 1; }) < 0);
    CHECK(rig.vehicle().readings().safety().state() == SafetyState::Ready);
}

TEST_CASE("a packet that kills completes after its zeros; one that drives completes at once") {
    DaemonRig rig;
    rig.run_until_ready();
    std::vector<int32_t> packet(kPacketWords, 0);
    for (std::size_t i = 0; i < kThrust.size(); ++i)
        packet[i] = kThrust[i];
    std::optional<Result> drove;
    rig.packets().apply(packet, ":1.7", [&](const Result& r) { drove = r; });
    REQUIRE(drove.has_value()); // at once
    CHECK(drove->ok());
    REQUIRE(rig.run_until([&] { return each_ordered(rig.wire().events(), kThrust); }));
    rig.wire().clear();
    packet[kPacketKill] = 1;
    std::optional<std::vector<WireEvent>> at_completion;
    rig.packets().apply(packet, ":1.7", [&](const Result&) { at_completion = rig.wire().events(); });
    REQUIRE(rig.run_until([&] { return at_completion.has_value(); }));
    check_kill_output_first(*at_completion); // the completion comes after the zeros
    CHECK(rig.vehicle().readings().safety().kill_record().source == KillSource::Packet);
}

TEST_CASE("a thruster that stops answering kills the vehicle (source device); the kill stays until it answers") {
    DaemonRig rig;
    rig.run_until_ready();
    rig.wire().fail(5, ENXIO);
    REQUIRE(rig.run_until([&] { return rig.vehicle().readings().safety().state() == SafetyState::Killed; }));
    CHECK(rig.vehicle().readings().safety().kill_record().source == KillSource::Device);
    CHECK(rig.vehicle().clear_kill().status == Status::ThrusterUnreachable);
    rig.wire().fail(5, 0);
    REQUIRE(rig.run_until([&] { return !rig.daemon().bus().health().first_unreachable(); }));
    CHECK(rig.vehicle().clear_kill().ok());
}

TEST_CASE("a fitted Teensy absent at start keeps the vehicle killed by teensy-link-lost; ClearKill refused") {
    // The fakes have no SPI node: the Teensy the [spi] table says is fitted is absent.
    DaemonRig rig("loop_rate_hz = 50\n", "[spi]\nfitted = true\n");
    // Killed as the failsafes start, before any loop cycle: never ready, not even armed at start.
    CHECK(rig.vehicle().readings().safety().state() == SafetyState::Killed);
    CHECK(rig.vehicle().readings().kill_source_name() == "failsafe");
    CHECK(rig.daemon().teensy().loss() == TeensyLoss::Absent);
    rig.run_for(300);
    REQUIRE(rig.daemon().failsafes().active().size() == 1);
    CHECK(rig.daemon().failsafes().active()[0].condition == FailsafeCondition::TeensyLinkLost);
    const Result r = rig.vehicle().clear_kill();
    CHECK(r.status == Status::FailsafeActive);
    CHECK_THAT(r.message, Catch::Contains("teensy-link-lost"));
    CHECK(rig.vehicle().readings().safety().state() == SafetyState::Killed);
    check_kill_output_first(rig.wire().events());
}

TEST_CASE("a Teensy not fitted and absent is no failsafe") {
    DaemonRig rig("loop_rate_hz = 50\n", "[spi]\nfitted = false\nsilence_ms = 50\n");
    rig.run_until_ready();
    rig.run_for(200); // several silences long
    CHECK(rig.vehicle().readings().safety().state() == SafetyState::Ready);
    CHECK(rig.daemon().failsafes().active().empty());
    CHECK(rig.daemon().teensy().loss() == TeensyLoss::None);
}
