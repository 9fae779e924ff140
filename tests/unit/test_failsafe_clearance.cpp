// daemon/failsafe/FailsafeClearance on a VehicleDaemon on the fakes (DaemonRig): a thruster's
// hall fault, configured to kill, read from its status replies on the fake wire. ClearKill is
// refused by the failsafe's name and names the way out; ClearKillOverride of another condition,
// of a fixed one or of an unknown name is refused and changes nothing; naming it clears the kill,
// and the failsafe only warns (the pilot drives on) until it clears; once it clears, the override
// is spent and the next fault kills again. Another failsafe that holds still refuses by its name.
// Over D-Bus (ServiceRig), a client's override is announced: Failsafes shows the failsafe warning.
#include "tests/unit/fakes/daemon_rig.hpp"
#include "tests/unit/fakes/service_rig.hpp"

#include "core/failsafe.hpp"
#include "core/safety.hpp"
#include "tests/catch.hpp"

#include <string>
#include <tuple>
#include <vector>

using namespace caracara;
using namespace caracara::test;

namespace {

const std::vector<int32_t> kDrive{1000, -2000, 3000, -4000, 500, -500, 1500, -1500};
const std::vector<int32_t> kDriveOn{1200, 1200, 1200, 1200, 1200, 1200, 1200, 1200};
constexpr std::size_t kFaulty = 6;
// Every thruster's status read each cycle; orders that stand (no command timeout in the test).
const char* const kControl = "loop_rate_hz = 50\nstatus_reads_per_tick = 8\ncommand_timeout_ms = 60000\n";
const char* const kHallKills = "[failsafe.hall]\naction = \"kill\"\npersistence_ms = 0\n";

bool killed(DaemonRig& rig) { return rig.vehicle().readings().safety().state() == SafetyState::Killed; }

// Driving kDrive, then thruster kFaulty reports a hall fault: killed by the failsafe, the kill
// output asserted and every thruster zeroed.
void hall_kill(DaemonRig& rig) {
    rig.run_until_ready();
    REQUIRE(rig.vehicle().motors().set_thrust(kDrive, ":1.7").ok());
    REQUIRE(rig.run_until([&] { return each_ordered(rig.wire().events(), kDrive); }));
    rig.wire().clear();
    rig.wire().set_faults(kFaulty, condition_fault_bit(FailsafeCondition::Hall));
    REQUIRE(rig.run_until([&] { return killed(rig); }));
    REQUIRE(rig.run_until([&] {
        const auto ev = rig.wire().events();
        const long at = kill_output(ev, 1);
        return at >= 0 && all_zeroed(ev, at);
    }));
    CHECK(rig.vehicle().readings().kill_source_name() == "failsafe");
}

// The one active failsafe: hall kill on kFaulty, overridden or not.
void check_hall(DaemonRig& rig, bool overridden) {
    const auto& active = rig.daemon().failsafes().active();
    REQUIRE(active.size() == 1);
    CHECK(active[0].condition == FailsafeCondition::Hall);
    CHECK(active[0].action == FailsafeAction::Kill);
    CHECK(active[0].thruster == static_cast<int>(kFaulty));
    CHECK(active[0].overridden == overridden);
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

} // namespace

TEST_CASE("ClearKillOverride: refused for any other name; naming the holding failsafe clears the kill, and it warns until it clears") {
    DaemonRig rig(kControl, kHallKills);
    hall_kill(rig);
    FailsafeMonitor& fs = rig.daemon().failsafes();

    const Result plain = rig.vehicle().clear_kill();
    CHECK(plain.status == Status::FailsafeActive);
    CHECK(has(plain.message, "hall"));
    CHECK(has(plain.message, "ClearKillOverride(\"hall\")")); // the way out, named

    // Another overridable condition: hall still holds, and refuses by its name.
    const Result other = fs.clear_kill_override("stall", ":1.7");
    CHECK(other.status == Status::FailsafeActive);
    CHECK(has(other.message, "hall"));
    // A fixed one cannot be overridden; an unknown name is no condition.
    const Result fixed = fs.clear_kill_override("bus-lost", ":1.7");
    CHECK(fixed.status == Status::FailsafeActive);
    CHECK(has(fixed.message, "fixed at kill"));
    CHECK(fs.clear_kill_override("leak", ":1.7").status == Status::InvalidValue);
    // None of them changed anything: still killed, hall not overridden, nothing driven.
    CHECK(killed(rig));
    check_hall(rig, false);

    rig.wire().clear();
    REQUIRE(fs.clear_kill_override("hall", ":1.7").ok());
    check_hall(rig, true);
    CHECK(fs.active()[0].effective() == FailsafeAction::Warn);
    REQUIRE(rig.run_until([&] { return rig.vehicle().readings().may_drive(); }));
    // The pilot drives on, deliberately, with the fault still read every cycle.
    REQUIRE(rig.vehicle().motors().set_thrust(kDriveOn, ":1.7").ok());
    REQUIRE(rig.run_until([&] { return each_ordered(rig.wire().events(), kDriveOn); }));
    rig.run_for(300); // six readings of the monitor, each with the fault
    CHECK_FALSE(killed(rig));
    CHECK(kill_output(rig.wire().events(), 1) < 0);
    check_hall(rig, true);
    // An overridden failsafe no longer stands in the way of a plain ClearKill.
    REQUIRE(rig.vehicle().kill(KillSource::DBus, "test").ok());
    CHECK(rig.vehicle().clear_kill().ok());

    // The fault clears: so does the failsafe, and the override with it. The next fault kills.
    rig.wire().set_faults(kFaulty, 0);
    REQUIRE(rig.run_until([&] { return fs.active().empty(); }));
    REQUIRE(rig.run_until([&] { return rig.vehicle().readings().may_drive(); }));
    REQUIRE(rig.vehicle().motors().set_thrust(kDrive, ":1.7").ok());
    rig.wire().clear();
    rig.wire().set_faults(kFaulty, condition_fault_bit(FailsafeCondition::Hall));
    REQUIRE(rig.run_until([&] { return killed(rig); }));
    CHECK(rig.vehicle().readings().kill_source_name() == "failsafe");
    check_hall(rig, false);
    CHECK(rig.vehicle().clear_kill().status == Status::FailsafeActive);
}

TEST_CASE("ClearKillOverride: another failsafe that holds refuses by its name, and the named one is not overridden") {
    DaemonRig rig(kControl, kHallKills);
    hall_kill(rig);
    FailsafeMonitor& fs = rig.daemon().failsafes();
    fs.push(FailsafeCondition::TeensyLinkLost, true, "test: the Teensy went away");
    rig.wire().clear();

    const Result r = fs.clear_kill_override("hall", ":1.7");
    CHECK(r.status == Status::FailsafeActive);
    CHECK(has(r.message, "teensy-link-lost"));
    CHECK(killed(rig));
    REQUIRE(fs.active().size() == 2);
    for (const ActiveFailsafe& f : fs.active())
        CHECK_FALSE(f.overridden);
    rig.run_for(60);
    CHECK(find(rig.wire().events(), [](const WireEvent& e) { return e.kind == WireEvent::Kind::Order && e.value != 0; }) < 0);

    // Once the link is back, the same call goes through.
    fs.push(FailsafeCondition::TeensyLinkLost, false, "test: back");
    REQUIRE(fs.clear_kill_override("hall", ":1.7").ok());
    check_hall(rig, true);
}

TEST_CASE("ClearKillOverride: nothing to clear while not killed; the failsafe is not overridden by the attempt") {
    // hall surfaces: the vehicle ascends (not killed) for as long as the test looks.
    DaemonRig rig(kControl, "[failsafe.hall]\naction = \"surface\"\npersistence_ms = 0\n"
                            "[failsafe.surface]\nheave = -0.5\nduration_ms = 60000\n");
    rig.run_until_ready();
    FailsafeMonitor& fs = rig.daemon().failsafes();
    rig.wire().set_faults(kFaulty, condition_fault_bit(FailsafeCondition::Hall));
    REQUIRE(rig.run_until([&] { return fs.surfacing_until() != 0; }));
    CHECK(fs.clear_kill_override("hall", ":1.7").status == Status::NotKilled);
    REQUIRE(fs.active().size() == 1);
    CHECK_FALSE(fs.active()[0].overridden);
    CHECK(fs.surfacing_until() != 0);
}

TEST_CASE("ClearKillOverride over D-Bus: the caller's override is announced; Failsafes shows the failsafe warning") {
    ServiceRig s(kControl, kHallKills);
    hall_kill(s.rig());
    using Row = std::tuple<std::string, std::string, int32_t>;
    std::vector<Row> announced; // the last Failsafes announced
    s.watch_property(dbus::kRootPath, "Failsafes", "a(ssi)", [&](sd_bus_message* m) {
        announced.clear();
        sd_bus_message_enter_container(m, 'a', "(ssi)");
        const char *condition = nullptr, *action = nullptr;
        int32_t thruster = 0;
        while (sd_bus_message_read(m, "(ssi)", &condition, &action, &thruster) > 0)
            announced.emplace_back(condition, action, thruster);
        sd_bus_message_exit_container(m);
    });

    REQUIRE(s.call(dbus::kRootPath, dbus::kVehicleIface, "ClearKillOverride", "s", "hall").ok());
    const std::vector<Row> warns{{"hall", "warn", static_cast<int32_t>(kFaulty)}};
    CHECK(s.rig().run_until([&] { return announced == warns; }));
    CHECK(s.text(dbus::kRootPath, dbus::kVehicleIface, "State") != "killed");
}
