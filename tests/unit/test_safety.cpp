#include "core/safety.hpp"

#include "tests/catch.hpp"

using namespace caracara;

namespace {

constexpr uint64_t kT0 = 1'000'000'000'000;  // an arbitrary monotonic start time
constexpr uint64_t ms(uint64_t v) { return ms_to_ns(v); }

// A machine past its arming delay.
SafetyMachine ready_machine(uint64_t& now) {
    SafetyMachine s(SafetyConfig{}, false, kT0);
    now = kT0 + ms(3000);
    s.tick(now);
    REQUIRE(s.state() == SafetyState::Ready);
    return s;
}

} // namespace

TEST_CASE("startup arms for 3 s with zero output, then becomes ready") {
    SafetyMachine s(SafetyConfig{}, false, kT0);
    CHECK(s.state() == SafetyState::Arming);
    CHECK_FALSE(s.may_drive());
    CHECK_FALSE(s.kill_output_asserted());
    CHECK(s.arming_remaining_ns(kT0) == ms(3000));
    CHECK(s.next_deadline() == kT0 + ms(3000));

    const SafetyAction refused = s.accept_command(kT0 + ms(1000));
    CHECK(refused.error == SafetyError::NotReady);
    CHECK(error_name(refused.error) == "NotReady");
    CHECK_THAT(refused.message, Catch::Contains("arming") && Catch::Contains("2000 ms"));

    SafetyAction a = s.tick(kT0 + ms(2999));
    CHECK_FALSE(a.state_changed);
    CHECK(s.state() == SafetyState::Arming);
    CHECK_FALSE(s.may_drive());

    a = s.tick(kT0 + ms(3000));
    CHECK(a.state_changed);
    CHECK(s.state() == SafetyState::Ready);
    CHECK(s.may_drive());
    CHECK(s.accept_command(kT0 + ms(3001)).ok());
    CHECK(s.command_active());
}

TEST_CASE("a timestamp from before the arming start does not end arming") {
    SafetyMachine s(SafetyConfig{}, false, kT0);
    s.tick(kT0 - ms(10000));
    CHECK(s.state() == SafetyState::Arming);
}

TEST_CASE("the arming delay is configurable") {
    SafetyConfig cfg;
    cfg.arming_delay_ns = ms(100);
    SafetyMachine s(cfg, false, kT0);
    s.tick(kT0 + ms(99));
    CHECK(s.state() == SafetyState::Arming);
    s.tick(kT0 + ms(100));
    CHECK(s.state() == SafetyState::Ready);
}

TEST_CASE("starting with the kill switch set starts killed") {
    SafetyMachine s(SafetyConfig{}, true, kT0);
    CHECK(s.state() == SafetyState::Killed);
    CHECK(s.kill_record().source == KillSource::Switch);
    CHECK(s.kill_output_asserted());
    CHECK(s.next_deadline() == SafetyMachine::kNoDeadline);
    s.tick(kT0 + ms(60000));
    CHECK(s.state() == SafetyState::Killed);

    const SafetyAction a = s.clear_kill(kT0 + ms(1));
    CHECK(a.error == SafetyError::KillSwitchSet);
    CHECK(error_name(a.error) == "KillSwitchSet");
    CHECK(s.state() == SafetyState::Killed);

    s.switch_changed(false, kT0 + ms(2));
    CHECK(s.state() == SafetyState::Killed);  // releasing the switch does not clear the kill
    CHECK(s.clear_kill(kT0 + ms(3)).ok());
    CHECK(s.state() == SafetyState::Arming);
}

TEST_CASE("a kill zeroes at once, drops commands and latches") {
    for (KillSource src : {KillSource::DBus, KillSource::Switch, KillSource::Packet, KillSource::Bus}) {
        INFO(kill_source_name(src));
        uint64_t now = 0;
        SafetyMachine s = ready_machine(now);
        REQUIRE(s.accept_command(now, ":1.42").ok());
        const SafetyAction a = src == KillSource::Switch ? s.switch_changed(true, now + 1)
                                                         : s.kill(src, now + 1, "test");
        CHECK(a.ok());
        CHECK(a.state_changed);
        CHECK(a.zero_outputs);
        CHECK(a.clear_commands);
        CHECK(s.state() == SafetyState::Killed);
        CHECK(s.kill_record().source == src);
        CHECK(s.kill_record().at == now + 1);
        CHECK(s.kill_output_asserted());
        CHECK_FALSE(s.may_drive());
        CHECK_FALSE(s.command_active());
        CHECK(s.commands().client().empty());

        // Latched: time passing changes nothing, commands are refused.
        s.tick(now + ms(600000));
        CHECK(s.state() == SafetyState::Killed);
        const SafetyAction r = s.accept_command(now + ms(600001));
        CHECK(r.error == SafetyError::NotReady);
        CHECK_THAT(r.message, Catch::Contains("killed"));
    }
    CHECK(kill_source_name(KillSource::DBus) == "dbus");
    CHECK(kill_source_name(KillSource::Switch) == "switch");
    CHECK(kill_source_name(KillSource::Packet) == "packet");
    CHECK(kill_source_name(KillSource::Bus) == "bus");
    CHECK(kill_source_name(KillSource::Device) == "device");
}

TEST_CASE("a second kill keeps the first source and still asks for zero") {
    uint64_t now = 0;
    SafetyMachine s = ready_machine(now);
    s.kill(KillSource::Packet, now);
    const SafetyAction a = s.kill(KillSource::Bus, now + 1, "bus recovery failed");
    CHECK(a.ok());
    CHECK_FALSE(a.state_changed);
    CHECK(a.zero_outputs);
    CHECK(s.kill_record().source == KillSource::Packet);
    CHECK(s.kill_record().at == now);
}

TEST_CASE("a kill during arming stops the arming") {
    SafetyMachine s(SafetyConfig{}, false, kT0);
    s.kill(KillSource::DBus, kT0 + ms(1000));
    s.tick(kT0 + ms(5000));
    CHECK(s.state() == SafetyState::Killed);
}

TEST_CASE("clearing needs a kill, the switch released, then a full arming delay") {
    uint64_t now = 0;
    SafetyMachine s = ready_machine(now);

    SafetyAction a = s.clear_kill(now);
    CHECK(a.error == SafetyError::NotKilled);
    CHECK(error_name(a.error) == "NotKilled");
    CHECK(s.state() == SafetyState::Ready);

    s.kill(KillSource::DBus, now);
    s.switch_changed(true, now + 1);  // switch set while already killed
    CHECK(s.kill_record().source == KillSource::DBus);
    a = s.clear_kill(now + 2);
    CHECK(a.error == SafetyError::KillSwitchSet);
    CHECK(s.state() == SafetyState::Killed);

    s.switch_changed(false, now + 3);
    const uint64_t cleared = now + ms(10);
    a = s.clear_kill(cleared);
    CHECK(a.ok());
    CHECK(a.state_changed);
    CHECK(a.zero_outputs);
    CHECK(s.state() == SafetyState::Arming);
    CHECK(s.kill_record().source == KillSource::None);
    CHECK_FALSE(s.kill_output_asserted());
    CHECK_FALSE(s.may_drive());
    CHECK(s.accept_command(cleared + ms(2999)).error == SafetyError::NotReady);

    s.tick(cleared + ms(2999));
    CHECK(s.state() == SafetyState::Arming);
    s.tick(cleared + ms(3000));
    CHECK(s.state() == SafetyState::Ready);
    // Nothing resumes by itself: no command is active until a new one arrives.
    CHECK_FALSE(s.command_active());
}

TEST_CASE("the kill switch kills from ready and keeps the vehicle killed while set") {
    uint64_t now = 0;
    SafetyMachine s = ready_machine(now);
    s.switch_changed(true, now);
    CHECK(s.state() == SafetyState::Killed);
    CHECK(s.kill_record().source == KillSource::Switch);
    CHECK(s.kill_switch_set());
    CHECK(s.clear_kill(now + ms(1)).error == SafetyError::KillSwitchSet);
    s.switch_changed(false, now + ms(2));
    CHECK_FALSE(s.kill_switch_set());
    CHECK(s.state() == SafetyState::Killed);
    CHECK(s.clear_kill(now + ms(3)).ok());
}

TEST_CASE("power-off is irreversible") {
    uint64_t now = 0;
    SafetyMachine s = ready_machine(now);
    REQUIRE(s.accept_command(now).ok());
    SafetyAction a = s.power_off(now + 1);
    CHECK(a.ok());
    CHECK(a.state_changed);
    CHECK(a.zero_outputs);
    CHECK(a.clear_commands);
    CHECK(s.state() == SafetyState::PoweredOff);
    CHECK(s.kill_output_asserted());
    CHECK_FALSE(s.may_drive());

    a = s.power_off(now + 2);
    CHECK(a.error == SafetyError::PoweredOff);
    CHECK(error_name(a.error) == "PoweredOff");
    CHECK(s.clear_kill(now + 3).error == SafetyError::PoweredOff);
    CHECK(s.accept_command(now + 4).error == SafetyError::PoweredOff);
    a = s.kill(KillSource::DBus, now + 5);
    CHECK(a.ok());
    CHECK(a.zero_outputs);
    CHECK_FALSE(a.state_changed);
    s.switch_changed(true, now + 6);
    s.switch_changed(false, now + 7);
    s.tick(now + ms(100000));
    CHECK(s.state() == SafetyState::PoweredOff);

    // Also from killed and from arming.
    SafetyMachine k(SafetyConfig{}, true, kT0);
    CHECK(k.power_off(kT0).ok());
    CHECK(k.state() == SafetyState::PoweredOff);
    SafetyMachine arming(SafetyConfig{}, false, kT0);
    CHECK(arming.power_off(kT0).ok());
    arming.tick(kT0 + ms(5000));
    CHECK(arming.state() == SafetyState::PoweredOff);
}

TEST_CASE("a silent command stream zeroes the output without killing") {
    uint64_t now = 0;
    SafetyMachine s = ready_machine(now);
    REQUIRE(s.accept_command(now, ":1.7").ok());
    CHECK(s.next_deadline() == now + ms(500));

    SafetyAction a = s.tick(now + ms(499));
    CHECK_FALSE(a.zero_outputs);
    CHECK(s.command_active());

    REQUIRE(s.accept_command(now + ms(400), ":1.7").ok());  // a fresh command restarts the watchdog
    a = s.tick(now + ms(899));
    CHECK_FALSE(a.command_stale);

    a = s.tick(now + ms(900));
    CHECK(a.ok());
    CHECK(a.command_stale);
    CHECK(a.zero_outputs);
    CHECK(a.clear_commands);
    CHECK_FALSE(a.state_changed);
    CHECK(s.state() == SafetyState::Ready);  // not a kill
    CHECK(s.kill_record().source == KillSource::None);
    CHECK_FALSE(s.kill_output_asserted());
    CHECK_FALSE(s.command_active());

    // Reported once, and the next command drives again without any clear.
    CHECK_FALSE(s.tick(now + ms(2000)).command_stale);
    CHECK(s.accept_command(now + ms(2001)).ok());
    CHECK(s.command_active());
}

TEST_CASE("the command timeout is configurable") {
    SafetyConfig cfg;
    cfg.arming_delay_ns = 0;
    cfg.command_timeout_ns = ms(50);
    SafetyMachine s(cfg, false, kT0);
    s.tick(kT0);
    REQUIRE(s.accept_command(kT0).ok());
    CHECK_FALSE(s.tick(kT0 + ms(49)).command_stale);
    CHECK(s.tick(kT0 + ms(50)).command_stale);
}

TEST_CASE("the commanding client leaving zeroes the output without killing") {
    uint64_t now = 0;
    SafetyMachine s = ready_machine(now);
    REQUIRE(s.accept_command(now, ":1.7").ok());
    CHECK(s.commands().client() == ":1.7");

    SafetyAction a = s.client_left(":1.9", now + 1);  // someone else
    CHECK_FALSE(a.zero_outputs);
    CHECK(s.command_active());

    a = s.client_left(":1.7", now + 2);
    CHECK(a.ok());
    CHECK(a.zero_outputs);
    CHECK(a.clear_commands);
    CHECK(s.state() == SafetyState::Ready);
    CHECK_FALSE(s.command_active());
    CHECK(s.next_deadline() == SafetyMachine::kNoDeadline);

    // The latest commander takes over.
    REQUIRE(s.accept_command(now + 3, ":1.7").ok());
    REQUIRE(s.accept_command(now + 4, ":1.8").ok());
    CHECK_FALSE(s.client_left(":1.7", now + 5).zero_outputs);
    CHECK(s.client_left(":1.8", now + 6).zero_outputs);
}

TEST_CASE("pilot lost: a pilot left and none remains, while armed; readers are no pilots") {
    uint64_t now = 0;
    SafetyMachine s = ready_machine(now);
    s.client_left(":1.3", now); // a reader (status, ClearKill) that never commanded
    CHECK_FALSE(s.pilot_lost());

    REQUIRE(s.accept_command(now, ":1.7").ok());
    REQUIRE(s.accept_command(now, ":1.8").ok()); // a second tab, commanding now
    s.client_left(":1.8", now + 1);              // the commanding one leaves: zeros...
    CHECK_FALSE(s.pilot_lost());                 // ... but :1.7 is a pilot still
    CHECK(s.pilots().connected() == 1);
    s.client_left(":1.7", now + 2); // no longer commanding, still a pilot: the last one
    CHECK(s.pilot_lost());
    CHECK(s.state() == SafetyState::Ready); // the kill is the failsafe's, after its persistence

    REQUIRE(s.accept_command(now + 3, ":1.9").ok()); // a new pilot ends it
    CHECK_FALSE(s.pilot_lost());
    s.client_left(":1.9", now + 4);
    CHECK(s.pilot_lost());

    // The kill ends it (nothing left to lose), and ClearKill arms with nobody piloting.
    s.kill(KillSource::Failsafe, now + 5, "pilot-lost kill");
    CHECK_FALSE(s.pilot_lost());
    REQUIRE(s.clear_kill(now + 6).ok());
    CHECK_FALSE(s.pilot_lost());
    CHECK(s.pilots().connected() == 0);
}

TEST_CASE("pilot lost: a pilot the command timeout zeroed is a pilot still") {
    uint64_t now = 0;
    SafetyMachine s = ready_machine(now);
    REQUIRE(s.accept_command(now, ":1.7").ok());
    const SafetyAction stale = s.tick(now + s.config().command_timeout_ns);
    CHECK(stale.command_stale);
    CHECK(s.state() == SafetyState::Ready); // a zero, not a kill
    CHECK_FALSE(s.pilot_lost());
    CHECK_FALSE(s.client_left(":1.7", now + s.config().command_timeout_ns + 1).zero_outputs); // already zero
    CHECK(s.pilot_lost());
}

TEST_CASE("pilot lost: a refused command makes no pilot; power-off forgets them") {
    SafetyMachine s(SafetyConfig{}, false, kT0);
    CHECK_FALSE(s.accept_command(kT0, ":1.7").ok()); // arming: refused
    s.client_left(":1.7", kT0 + 1);
    CHECK_FALSE(s.pilot_lost());
    uint64_t now = 0;
    SafetyMachine r = ready_machine(now);
    REQUIRE(r.accept_command(now, ":1.7").ok());
    r.client_left(":1.7", now + 1);
    REQUIRE(r.pilot_lost());
    r.power_off(now + 2);
    CHECK_FALSE(r.pilot_lost());
}

TEST_CASE("state names") {
    CHECK(state_name(SafetyState::Arming) == "arming");
    CHECK(state_name(SafetyState::Ready) == "ready");
    CHECK(state_name(SafetyState::Killed) == "killed");
    CHECK(state_name(SafetyState::PoweredOff) == "powered-off");
}

TEST_CASE("start killed: source start until ClearKill, and any real kill names itself instead") {
    SafetyConfig cfg;
    cfg.start_killed = true;
    SafetyMachine s(cfg, false, kT0);
    CHECK(s.state() == SafetyState::Killed);
    CHECK(s.kill_record().source == KillSource::Start);
    CHECK(kill_source_name(s.kill_record().source) == "start");
    CHECK(s.kill_output_asserted());
    CHECK_FALSE(s.may_drive());
    CHECK(s.next_deadline() == SafetyMachine::kNoDeadline); // nothing ends a start kill by itself
    CHECK(s.tick(kT0 + ms(60000)).state_changed == false);
    CHECK(s.state() == SafetyState::Killed);
    CHECK_FALSE(s.accept_command(kT0 + ms(1), "client").ok());

    // The switch set at start: the kill is the switch's now, and ClearKill wants it released.
    SafetyAction a = s.switch_changed(true, kT0 + ms(2));
    CHECK(a.zero_outputs);
    CHECK(s.kill_record().source == KillSource::Switch);
    CHECK(s.clear_kill(kT0 + ms(3)).error == SafetyError::KillSwitchSet);
    s.switch_changed(false, kT0 + ms(4));
    CHECK(s.clear_kill(kT0 + ms(5)).ok());
    CHECK(s.state() == SafetyState::Arming);
}

TEST_CASE("start killed: ClearKill arms it; a second kill keeps its first real source") {
    SafetyConfig cfg;
    cfg.start_killed = true;
    SafetyMachine s(cfg, false, kT0);
    REQUIRE(s.clear_kill(kT0 + ms(10)).ok());
    s.tick(kT0 + ms(10) + cfg.arming_delay_ns);
    CHECK(s.state() == SafetyState::Ready);
    s.kill(KillSource::DBus, kT0 + ms(4000));
    s.kill(KillSource::Packet, kT0 + ms(4001));
    CHECK(s.kill_record().source == KillSource::DBus);
}

TEST_CASE("the default machine (arm at start) still starts arming") {
    SafetyMachine s(SafetyConfig{}, false, kT0);
    CHECK(s.state() == SafetyState::Arming);
    CHECK(s.kill_record().source == KillSource::None);
}
