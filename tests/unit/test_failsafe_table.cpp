// The failsafe table (core/failsafe.hpp, kFailsafeTable), row by row: each condition raises its
// action; each fixed one, pushed to the FailsafeMonitor of a VehicleDaemon on the fakes, kills at
// once (or after pilot-lost's persistence) with the row's kill source, judged by the fake wire
// (kill output first, every thruster zero), and a ClearKill arms again once it clears.
#include "tests/unit/fakes/daemon_rig.hpp"

#include "core/clock.hpp"
#include "core/failsafe.hpp"
#include "core/failsafe_policy.hpp"
#include "tests/catch.hpp"

#include <string>
#include <vector>

using namespace caracara;
using namespace caracara::test;
using Kind = WireEvent::Kind;

namespace {

const std::vector<int32_t> kThrust{1000, -2000, 3000, -4000, 500, -500, 1500, -1500};

long kill_output_asserted(const std::vector<WireEvent>& ev) {
    return find(ev, [](const WireEvent& e) { return e.kind == Kind::KillOutput && e.value == 1; });
}

bool zeroed_after(const std::vector<WireEvent>& ev, long from) {
    for (std::size_t i = 0; i < kThrust.size(); ++i)
        if (find(ev, [&](const WireEvent& e) { return e.is_order(i, 0); }, from) < 0)
            return false;
    return true;
}

// What the policy raises for row `c` with the default rules, once it has held its persistence.
std::vector<FailsafeTransition> raised_by(FailsafeCondition c) {
    const FailsafeSettings defaults;
    FailsafePolicy p(defaults, 8);
    const uint64_t held = ms_to_ns(defaults.rule(c).persistence_ms);
    FailsafeTransitions ts = condition_is_fixed(c) ? p.set_condition(c, true, 0)
                                                   : p.observe(2, condition_fault_bit(c), 20, 0);
    const FailsafeTransitions due = p.tick(held);
    ts.insert(ts.end(), due.begin(), due.end());
    return ts;
}

} // namespace

TEST_CASE("the failsafe table: each condition raises its row's action") {
    for (const FailsafeRow& row : kFailsafeTable) {
        INFO(condition_name(row.condition));
        const auto ts = raised_by(row.condition);
        REQUIRE(ts.size() == 1);
        CHECK(ts[0].raised);
        CHECK(ts[0].failsafe.condition == row.condition);
        CHECK(ts[0].failsafe.action == row.default_rule.action);
        CHECK(ts[0].failsafe.thruster == (condition_is_fixed(row.condition) ? -1 : 2));
        // The ones that protect people are fixed at kill.
        if (condition_is_fixed(row.condition))
            CHECK(row.default_rule.action == FailsafeAction::Kill);
    }
}

TEST_CASE("the failsafe table: each fixed condition pushed kills with its row's kill source, at once") {
    for (const FailsafeRow& row : kFailsafeTable) {
        if (!condition_is_fixed(row.condition))
            continue;
        const std::string name(condition_name(row.condition));
        INFO(name);
        DaemonRig rig("loop_rate_hz = 50\n", "[failsafe.pilot-lost]\npersistence_ms = 200\n");
        rig.run_until_ready();
        REQUIRE(rig.vehicle().motors().set_thrust(kThrust, ":1.7").ok());
        rig.run_for(60);
        rig.wire().clear();
        const uint64_t pushed_at = monotonic_ns();
        rig.daemon().failsafes().push(row.condition, true, "test: " + name + " holds");
        if (row.default_rule.persistence_ms == 0) {
            // Handled at once: killed before the loop runs again, not at the monitor's reading.
            CHECK(rig.vehicle().readings().safety().state() == SafetyState::Killed);
        } else {
            CHECK(rig.vehicle().readings().safety().state() == SafetyState::Ready);
            CHECK(rig.daemon().failsafes().pilot_lost_kill_at() >= pushed_at + ms_to_ns(200));
        }
        REQUIRE(rig.run_until([&] {
            const auto ev = rig.wire().events();
            const long at = kill_output_asserted(ev);
            return at >= 0 && zeroed_after(ev, at);
        }));
        if (row.default_rule.persistence_ms != 0)
            CHECK(monotonic_ns() - pushed_at >= ms_to_ns(200));
        CHECK(rig.vehicle().readings().kill_source_name() == kill_source_name(row.kill_source));
        // A source's own kill reads with the reason it pushed; a failsafe's, with its name.
        if (row.kill_source == KillSource::Failsafe)
            CHECK(rig.vehicle().readings().safety().kill_record().reason == name + " kill");
        else
            CHECK(rig.vehicle().readings().safety().kill_record().reason == "test: " + name + " holds");
        REQUIRE(rig.daemon().failsafes().active().size() == 1);
        CHECK(rig.daemon().failsafes().active()[0].condition == row.condition);
        rig.daemon().failsafes().push(row.condition, false, "test: cleared");
        CHECK(rig.daemon().failsafes().active().empty());
        CHECK(rig.vehicle().clear_kill().ok());
    }
}

TEST_CASE("the failsafe table: teensy-link-lost keeps the kill while it holds, by its name") {
    DaemonRig rig;
    rig.run_until_ready();
    rig.daemon().failsafes().push(FailsafeCondition::TeensyLinkLost, true, "test: the Teensy went away");
    REQUIRE(rig.vehicle().readings().safety().state() == SafetyState::Killed);
    const Result r = rig.vehicle().clear_kill();
    CHECK(r.status == Status::FailsafeActive);
    CHECK(r.message.find("teensy-link-lost") != std::string::npos);
    rig.daemon().failsafes().push(FailsafeCondition::TeensyLinkLost, false, "test: back");
    CHECK(rig.vehicle().clear_kill().ok());
}

TEST_CASE("safety-line-lost: the kill output gone under a running vehicle kills, source device, until it is back") {
    DaemonRig rig;
    rig.run_until_ready();
    REQUIRE(rig.vehicle().motors().set_thrust(kThrust, ":1.7").ok());
    rig.run_for(60);
    rig.wire().clear();
    rig.gpio().set_outputs_gone(true); // found by the outputs' read-back (every 100 ms)
    REQUIRE(rig.run_until([&] { return rig.vehicle().readings().safety().state() == SafetyState::Killed; }));
    CHECK(rig.vehicle().readings().kill_source_name() == "device");
    CHECK(rig.vehicle().readings().safety().kill_record().reason == "kill output went away");
    REQUIRE(rig.run_until([&] { return zeroed_after(rig.wire().events(), 0); }));
    CHECK(rig.vehicle().clear_kill().status == Status::Hardware);
    rig.gpio().set_outputs_gone(false); // asked for again once a second: back asserted, and cleared
    REQUIRE(rig.run_until([&] { return rig.daemon().failsafes().active().empty(); }, 3000));
    CHECK(rig.vehicle().clear_kill().ok());
}

TEST_CASE("safety-line-lost: a kill output that fails as a Kill asserts it is decided after that kill, not inside it") {
    DaemonRig rig;
    rig.run_until_ready();
    REQUIRE(rig.vehicle().motors().set_thrust(kThrust, ":1.7").ok());
    rig.run_for(60);
    rig.wire().clear();
    rig.gpio().set_outputs_gone(true);
    CHECK(rig.vehicle().kill(KillSource::DBus, "test").ok());
    // The Kill's own sequence ran to its end: killed by D-Bus, its zeros handed down.
    CHECK(rig.vehicle().readings().kill_source_name() == "dbus");
    CHECK(rig.daemon().failsafes().active().empty()); // not yet: right after the sequence
    REQUIRE(rig.run_until([&] { return !rig.daemon().failsafes().active().empty(); }, 500));
    CHECK(rig.daemon().failsafes().active()[0].condition == FailsafeCondition::SafetyLineLost);
    CHECK(rig.vehicle().readings().kill_source_name() == "dbus"); // the first kill's source is kept
    REQUIRE(rig.run_until([&] { return zeroed_after(rig.wire().events(), 0); }));
    rig.gpio().set_outputs_gone(false);
}
