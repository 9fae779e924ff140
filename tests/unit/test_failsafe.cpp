// The failsafe policy (core/failsafe_policy) and the [failsafe] table: persistence, the
// clearing rules of SeaBotix IDS 8.4.2, priorities when two conditions hold, the override,
// and the checker refusing to weaken a fixed condition.
#include "core/config.hpp"
#include "core/failsafe_policy.hpp"

#include "tests/catch.hpp"

#include <string>

using namespace caracara;

namespace {

constexpr uint64_t ms(uint64_t v) { return v * 1'000'000ull; }
constexpr uint8_t kOvertempBit = 1u << 0, kStallBit = 1u << 1, kHallBit = 1u << 2, kGroundBit = 1u << 3,
                  kWaterBit = 1u << 4;

FailsafeSettings settings(FailsafeCondition c, FailsafeAction a, uint32_t persistence_ms) {
    FailsafeSettings s;
    s.rule(c) = {a, persistence_ms};
    return s;
}

ActiveFailsafe fs(FailsafeCondition c, FailsafeAction a, int thruster) { return {c, a, thruster, false}; }

} // namespace

TEST_CASE("failsafe: a condition shorter than its persistence time does nothing") {
    FailsafePolicy p(settings(FailsafeCondition::WaterDetect, FailsafeAction::Surface, 2000), 8);
    CHECK(p.observe(3, kWaterBit, 20, ms(1000)).empty());
    CHECK(p.next_deadline() == ms(3000));
    CHECK(p.tick(ms(2999)).empty());
    CHECK(p.observe(3, 0, 20, ms(2500)).empty()); // gone before 2 s: nothing raised, nothing cleared
    CHECK(p.next_deadline() == FailsafePolicy::kNoDeadline);
    CHECK(p.tick(ms(5000)).empty());
    CHECK(p.active().empty());
    CHECK_FALSE(p.strongest());
}

TEST_CASE("failsafe: held for its persistence time it raises its action, and clears with its condition") {
    FailsafePolicy p(settings(FailsafeCondition::WaterDetect, FailsafeAction::Surface, 2000), 8);
    p.observe(3, kWaterBit, 20, ms(1000));
    CHECK(p.observe(3, kWaterBit, 20, ms(2000)).empty());
    const FailsafeTransitions up = p.tick(ms(3000));
    REQUIRE(up.size() == 1);
    CHECK(up[0] == FailsafeTransition{fs(FailsafeCondition::WaterDetect, FailsafeAction::Surface, 3), true});
    CHECK(p.strongest() == FailsafeAction::Surface);
    CHECK(p.blocking().size() == 1);
    CHECK(p.observe(3, kWaterBit, 20, ms(3100)).empty()); // raised once
    // IDS 8.4.2 remark 2: the flag clears when the resistance is above one megohm again.
    const FailsafeTransitions down = p.observe(3, 0, 20, ms(4000));
    REQUIRE(down.size() == 1);
    CHECK_FALSE(down[0].raised);
    CHECK(p.active().empty());
    CHECK(p.blocking().empty());
}

TEST_CASE("failsafe: persistence 0 raises at the first reading") {
    FailsafePolicy p(settings(FailsafeCondition::Stall, FailsafeAction::Exclude, 0), 8);
    const FailsafeTransitions up = p.observe(5, kStallBit, 20, ms(10));
    REQUIRE(up.size() == 1);
    CHECK(p.excluded(5));
    CHECK_FALSE(p.excluded(4));
    CHECK(p.blocking().empty()); // an exclusion does not stop a ClearKill
}

TEST_CASE("failsafe: overtemp sets at 110 C and clears at 100 C (IDS 8.4.2 remark 6)") {
    FailsafePolicy p(settings(FailsafeCondition::Overtemp, FailsafeAction::Exclude, 0), 8);
    CHECK(p.observe(2, 0, 109, ms(1)).empty());
    REQUIRE(p.observe(2, 0, 110, ms(2)).size() == 1);
    CHECK(p.excluded(2));
    CHECK(p.observe(2, 0, 105, ms(3)).empty()); // cooling, but above 100 C: still on
    CHECK(p.observe(2, 0, 101, ms(4)).empty());
    CHECK(p.excluded(2));
    const FailsafeTransitions down = p.observe(2, 0, 100, ms(5));
    REQUIRE(down.size() == 1);
    CHECK_FALSE(down[0].raised);
    CHECK_FALSE(p.excluded(2));
    CHECK(p.observe(2, 0, 105, ms(6)).empty()); // below the set point again: nothing
}

TEST_CASE("failsafe: the controller's overtemp bit is overtemp, whatever the temperature byte says") {
    FailsafePolicy p(settings(FailsafeCondition::Overtemp, FailsafeAction::Warn, 0), 8);
    REQUIRE(p.observe(0, kOvertempBit, 15, ms(1)).size() == 1);
    CHECK(p.strongest() == FailsafeAction::Warn);
    CHECK(p.observe(0, 0, 15, ms(2)).size() == 1); // the bit gone at 15 C: cleared
    CHECK(p.active().empty());
    REQUIRE(p.observe(1, kOvertempBit, std::nullopt, ms(3)).size() == 1); // legacy: no temperature
}

TEST_CASE("failsafe: a ground fault stays while its bit is held (until a power cycle, IDS 8.4.2 remark 3)") {
    FailsafePolicy p(settings(FailsafeCondition::GroundFault, FailsafeAction::Exclude, 500), 8);
    p.observe(6, kGroundBit, 20, ms(0));
    REQUIRE(p.tick(ms(500)).size() == 1);
    for (uint64_t t = 600; t < 5000; t += 160)
        CHECK(p.observe(6, kGroundBit, 20, ms(t)).empty());
    CHECK(p.excluded(6));
    CHECK(p.observe(6, 0, 20, ms(5000)).size() == 1); // the power cycle
    CHECK_FALSE(p.excluded(6));
}

TEST_CASE("failsafe: when two conditions hold the most severe action wins, exclusions add up") {
    FailsafeSettings s;
    s.rule(FailsafeCondition::WaterDetect) = {FailsafeAction::Surface, 0};
    s.rule(FailsafeCondition::Overtemp) = {FailsafeAction::Exclude, 0};
    s.rule(FailsafeCondition::Hall) = {FailsafeAction::Kill, 0};
    s.rule(FailsafeCondition::Stall) = {FailsafeAction::Warn, 0};
    FailsafePolicy p(s, 8);
    p.observe(1, kStallBit, 20, ms(1));
    CHECK(p.strongest() == FailsafeAction::Warn);
    p.observe(2, kOvertempBit, 20, ms(2));
    CHECK(p.strongest() == FailsafeAction::Exclude);
    p.observe(4, kOvertempBit | kWaterBit, 20, ms(3)); // two on one thruster
    CHECK(p.strongest() == FailsafeAction::Surface);
    CHECK(p.excluded(2));
    CHECK(p.excluded(4));
    CHECK(p.active().size() == 4);
    p.observe(7, kHallBit, 20, ms(4));
    CHECK(p.strongest() == FailsafeAction::Kill);
    CHECK(p.blocking().size() == 2);
    p.observe(7, 0, 20, ms(5));
    CHECK(p.strongest() == FailsafeAction::Surface); // the kill's condition gone, surface still holds
    p.observe(4, kOvertempBit, 20, ms(6));
    CHECK(p.strongest() == FailsafeAction::Exclude);
}

TEST_CASE("failsafe: an override makes its condition's kill or surface warn until it clears") {
    FailsafeSettings s;
    s.rule(FailsafeCondition::WaterDetect) = {FailsafeAction::Kill, 0};
    s.rule(FailsafeCondition::GroundFault) = {FailsafeAction::Exclude, 0};
    FailsafePolicy p(s, 8);
    p.observe(0, kWaterBit | kGroundBit, 20, ms(1));
    CHECK(p.strongest() == FailsafeAction::Kill);
    CHECK(p.override_condition(FailsafeCondition::Overtemp) == 0);
    CHECK(p.override_condition(FailsafeCondition::WaterDetect) == 1);
    CHECK(p.blocking().empty());
    CHECK(p.strongest() == FailsafeAction::Exclude);
    CHECK(p.excluded(0)); // the ground fault's exclusion stays
    CHECK(p.observe(0, kWaterBit | kGroundBit, 20, ms(2)).empty()); // not raised again while it holds
    p.observe(0, kGroundBit, 20, ms(3));                              // cleared ...
    REQUIRE(p.observe(0, kWaterBit | kGroundBit, 20, ms(4)).size() == 1); // ... and back: a kill again
    CHECK(p.strongest() == FailsafeAction::Kill);
}

TEST_CASE("failsafe: the vehicle's own conditions have thruster -1") {
    FailsafePolicy p(FailsafeSettings{}, 8);
    const FailsafeTransitions up = p.set_condition(FailsafeCondition::BusLost, true, ms(1));
    REQUIRE(up.size() == 1);
    CHECK(up[0].failsafe == fs(FailsafeCondition::BusLost, FailsafeAction::Kill, -1));
    CHECK(p.set_condition(FailsafeCondition::BusLost, false, ms(2)).size() == 1);
}

TEST_CASE("failsafe: pilot lost kills after its persistence; a pilot back within it ends it") {
    FailsafePolicy p(FailsafeSettings{}, 8); // 5000 ms by default
    CHECK(p.set_condition(FailsafeCondition::PilotLost, true, ms(100)).empty());
    CHECK(p.next_deadline() == ms(5100));
    CHECK(p.tick(ms(5099)).empty());
    CHECK(p.set_condition(FailsafeCondition::PilotLost, false, ms(5099)).empty()); // a pilot commands
    CHECK(p.tick(ms(9000)).empty());
    CHECK(p.set_condition(FailsafeCondition::PilotLost, true, ms(10000)).empty()); // from the new loss
    CHECK(p.set_condition(FailsafeCondition::PilotLost, true, ms(14999)).empty());
    const FailsafeTransitions up = p.set_condition(FailsafeCondition::PilotLost, true, ms(15000));
    REQUIRE(up.size() == 1);
    CHECK(up[0].failsafe == fs(FailsafeCondition::PilotLost, FailsafeAction::Kill, -1));
    CHECK(p.blocking().size() == 1);
    // The kill ends the condition: cleared, nothing holds a ClearKill.
    const FailsafeTransitions down = p.set_condition(FailsafeCondition::PilotLost, false, ms(15050));
    REQUIRE(down.size() == 1);
    CHECK_FALSE(down[0].raised);
    CHECK(p.blocking().empty());
}

TEST_CASE("failsafe: the pilot-lost countdown's end while it runs (PilotLostKillAt), none before or after") {
    FailsafeSettings s;
    s.rule(FailsafeCondition::PilotLost).persistence_ms = 3000;
    FailsafePolicy p(s, 8);
    CHECK(p.pending_deadline(FailsafeCondition::PilotLost) == FailsafePolicy::kNoDeadline);
    CHECK(p.set_condition(FailsafeCondition::PilotLost, true, ms(100)).empty());
    CHECK(p.pending_deadline(FailsafeCondition::PilotLost) == ms(3100));
    CHECK(p.set_condition(FailsafeCondition::PilotLost, true, ms(2000)).empty()); // still the first loss's end
    CHECK(p.pending_deadline(FailsafeCondition::PilotLost) == ms(3100));
    CHECK(p.pending_deadline(FailsafeCondition::BusLost) == FailsafePolicy::kNoDeadline);
    CHECK(p.set_condition(FailsafeCondition::PilotLost, true, ms(3100)).size() == 1); // raised: no countdown
    CHECK(p.pending_deadline(FailsafeCondition::PilotLost) == FailsafePolicy::kNoDeadline);
    CHECK(p.set_condition(FailsafeCondition::PilotLost, false, ms(3200)).size() == 1);
    CHECK(p.pending_deadline(FailsafeCondition::PilotLost) == FailsafePolicy::kNoDeadline);
}

TEST_CASE("failsafe: names on the wire") {
    for (std::size_t i = 0; i < kFailsafeConditionCount; ++i) {
        const auto c = static_cast<FailsafeCondition>(i);
        CHECK(condition_from_name(condition_name(c)) == c);
    }
    CHECK(condition_name(FailsafeCondition::KillSwitchUnreadable) == "kill-switch-unreadable");
    CHECK(action_name(FailsafeAction::Exclude) == "exclude");
    CHECK(action_from_name("surface") == FailsafeAction::Surface);
    CHECK_FALSE(action_from_name("disarm"));
}

TEST_CASE("[failsafe]: defaults, a full table, and the fixed conditions") {
    ConfigResult d = parse_config_string("");
    REQUIRE(d.ok());
    CHECK(d.config->failsafe.rule(FailsafeCondition::WaterDetect).action == FailsafeAction::Surface);
    CHECK(d.config->failsafe.rule(FailsafeCondition::PilotLost).action == FailsafeAction::Kill);
    CHECK(d.config->failsafe.rule(FailsafeCondition::PilotLost).persistence_ms == 5000);
    CHECK(d.config->failsafe.rule(FailsafeCondition::TeensyLinkLost).persistence_ms == 0);

    ConfigResult r = parse_config_string("[failsafe.water-detect]\naction = \"warn\"\npersistence_ms = 100\n"
                                         "[failsafe.hall]\naction = \"kill\"\n"
                                         "[failsafe.bus-lost]\naction = \"kill\"\n"
                                         "[failsafe.surface]\nheave = -0.3\nduration_ms = 4000\n");
    INFO(r.error());
    REQUIRE(r.ok());
    const FailsafeSettings& f = r.config->failsafe;
    CHECK(f.rule(FailsafeCondition::WaterDetect).action == FailsafeAction::Warn);
    CHECK(f.rule(FailsafeCondition::WaterDetect).persistence_ms == 100);
    CHECK(f.rule(FailsafeCondition::Hall).action == FailsafeAction::Kill);
    CHECK(f.rule(FailsafeCondition::Hall).persistence_ms == FailsafeSettings{}.rule(FailsafeCondition::Hall).persistence_ms);
    CHECK(f.surface.heave == Approx(-0.3));
    CHECK(f.surface.duration_ms == 4000);
}

TEST_CASE("[failsafe]: pilot-lost's persistence is the one a fixed condition may set") {
    const ConfigResult r = parse_config_string("[failsafe.pilot-lost]\naction = \"kill\"\npersistence_ms = 1500\n");
    INFO(r.error());
    REQUIRE(r.ok());
    CHECK(r.config->failsafe.rule(FailsafeCondition::PilotLost).persistence_ms == 1500);
    CHECK(r.config->failsafe.rule(FailsafeCondition::PilotLost).action == FailsafeAction::Kill);
}

TEST_CASE("[failsafe]: the checker refuses weakening a fixed condition, by name") {
    for (const char* cond : {"pilot-lost", "thruster-unreachable", "bus-lost", "teensy-link-lost",
                             "kill-switch-unreadable"})
        for (const char* action : {"warn", "exclude", "surface"}) {
            const ConfigResult r = parse_config_string(std::string("[failsafe.") + cond + "]\naction = \"" + action + "\"\n");
            INFO(cond << " " << action);
            REQUIRE_FALSE(r.ok());
            CHECK(r.error().find(std::string("failsafe.") + cond + ".action: FixedFailsafe") != std::string::npos);
        }
}

TEST_CASE("[failsafe]: bad tables get named errors") {
    auto err = [](const std::string& text) {
        const ConfigResult r = parse_config_string(text);
        CHECK_FALSE(r.ok());
        return r.error();
    };
    CHECK(err("[failsafe.leak]\naction = \"kill\"\n").find("failsafe.leak: is not a failsafe condition") != std::string::npos);
    CHECK(err("[failsafe.stall]\naction = \"disarm\"\n").find("failsafe.stall.action: must be") != std::string::npos);
    CHECK(err("[failsafe.stall]\npersistence_ms = -1\n").find("failsafe.stall.persistence_ms") != std::string::npos);
    CHECK(err("[failsafe.stall]\npersistance_ms = 1\n").find("did you mean 'failsafe.stall.persistence_ms'") !=
          std::string::npos);
    CHECK(err("[failsafe.bus-lost]\npersistence_ms = 1\n").find("unknown key 'failsafe.bus-lost.persistence_ms'") !=
          std::string::npos);
    CHECK(err("[failsafe.teensy-link-lost]\npersistence_ms = 1\n")
              .find("unknown key 'failsafe.teensy-link-lost.persistence_ms'") != std::string::npos);
    CHECK(err("[failsafe.pilot-lost]\npersistence_ms = 60001\n").find("failsafe.pilot-lost.persistence_ms") !=
          std::string::npos);
    CHECK(err("[failsafe.surface]\nheave = 0.5\n").find("failsafe.surface.heave: must be") != std::string::npos);
    CHECK(err("[failsafe.surface]\nduration_ms = 0\n").find("failsafe.surface.duration_ms") != std::string::npos);
}
