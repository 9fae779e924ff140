// Failsafes: a condition, the action it takes and how long it must hold first (the
// [failsafe] table; daemon/caracarad.toml.example gives the defaults and why). The five
// thruster conditions are the SeaBotix FAULT bits (SeaBotix IDS 8.4.2); the other six are
// the daemon's own safety conditions, fixed at kill. kFailsafeTable below is what kills the
// vehicle by itself: every automatic kill is one of its rows, raised by the source named
// there and carried out by the FailsafeMonitor (daemon/failsafe), the one automatic killer.
#pragma once

#include "core/enum_names.hpp"
#include "core/safety_state.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace caracara {

enum class FailsafeCondition : uint8_t {
    // A thruster's FAULT bits (SeaBotix IDS 8.4.2).
    WaterDetect,
    GroundFault,
    Overtemp,
    Stall,
    Hall,
    // Fixed at kill: they protect people.
    PilotLost,
    ThrusterUnreachable,
    BusLost,
    TeensyLinkLost,
    KillSwitchUnreadable,
    SafetyLineLost,
};
inline constexpr std::size_t kFailsafeConditionCount = 11;
inline constexpr std::size_t kThrusterConditionCount = 5; // WaterDetect..Hall
inline constexpr std::array<FailsafeCondition, kThrusterConditionCount> kThrusterConditions{
    FailsafeCondition::WaterDetect, FailsafeCondition::GroundFault, FailsafeCondition::Overtemp,
    FailsafeCondition::Stall, FailsafeCondition::Hall};

// In order of severity: when two conditions hold, the later action wins.
enum class FailsafeAction : uint8_t { Warn, Exclude, Surface, Kill };

template <>
struct EnumNames<FailsafeCondition> {
    static constexpr std::array<EnumName<FailsafeCondition>, kFailsafeConditionCount> table{{
        {FailsafeCondition::WaterDetect, "water-detect"},
        {FailsafeCondition::GroundFault, "ground-fault"},
        {FailsafeCondition::Overtemp, "overtemp"},
        {FailsafeCondition::Stall, "stall"},
        {FailsafeCondition::Hall, "hall"},
        {FailsafeCondition::PilotLost, "pilot-lost"},
        {FailsafeCondition::ThrusterUnreachable, "thruster-unreachable"},
        {FailsafeCondition::BusLost, "bus-lost"},
        {FailsafeCondition::TeensyLinkLost, "teensy-link-lost"},
        {FailsafeCondition::KillSwitchUnreadable, "kill-switch-unreadable"},
        {FailsafeCondition::SafetyLineLost, "safety-line-lost"},
    }};
};
template <>
struct EnumNames<FailsafeAction> {
    static constexpr std::array<EnumName<FailsafeAction>, 4> table{{
        {FailsafeAction::Warn, "warn"},
        {FailsafeAction::Exclude, "exclude"},
        {FailsafeAction::Surface, "surface"},
        {FailsafeAction::Kill, "kill"},
    }};
};
inline std::string_view condition_name(FailsafeCondition c) { return name_of(c); }
inline std::optional<FailsafeCondition> condition_from_name(std::string_view name) {
    return parse_name<FailsafeCondition>(name);
}
inline std::string_view action_name(FailsafeAction a) { return name_of(a); }
inline std::optional<FailsafeAction> action_from_name(std::string_view name) { return parse_name<FailsafeAction>(name); }

// Fixed at kill; the config checker refuses a weaker action.
constexpr bool condition_is_fixed(FailsafeCondition c) { return c >= FailsafeCondition::PilotLost; }
// The fixed ones' timing is the daemon's own, except pilot-lost's: how long a pilot has to come
// back (a reloaded page, a dropped SSH tunnel) before the vehicle is killed.
constexpr bool condition_has_persistence(FailsafeCondition c) {
    return !condition_is_fixed(c) || c == FailsafeCondition::PilotLost;
}
inline constexpr uint32_t kPilotLostPersistenceMs = 5000; // why: daemon/caracarad.toml.example
inline constexpr uint32_t kPilotLostPersistenceMaxMs = 60000;

struct FailsafeRule {
    FailsafeAction action = FailsafeAction::Warn;
    uint32_t persistence_ms = 0; // the condition must hold this long before the action
};

// One row per condition: its default rule and the source a kill by it carries (the journal's
// "KILLED by", D-Bus KillSource, the dive file). The thruster rows are read from each status
// reply by the FailsafeMonitor; every other row is pushed (holds / clears) by the object
// named beside it, and handled at once.
struct FailsafeRow {
    FailsafeCondition condition;
    FailsafeRule default_rule;
    KillSource kill_source;
};
inline constexpr std::array<FailsafeRow, kFailsafeConditionCount> kFailsafeTable{{
    // Why each default, for a slightly buoyant vehicle: daemon/caracarad.toml.example.
    {FailsafeCondition::WaterDetect, {FailsafeAction::Surface, 2000}, KillSource::Failsafe},
    {FailsafeCondition::GroundFault, {FailsafeAction::Exclude, 500}, KillSource::Failsafe},
    {FailsafeCondition::Overtemp, {FailsafeAction::Exclude, 2000}, KillSource::Failsafe},
    {FailsafeCondition::Stall, {FailsafeAction::Exclude, 1000}, KillSource::Failsafe},
    {FailsafeCondition::Hall, {FailsafeAction::Exclude, 1000}, KillSource::Failsafe},
    // daemon/vehicle/pilot_watch: the last pilot left the bus. The only fixed row with a
    // persistence of its own: the lost pilot's thrust is already zero.
    {FailsafeCondition::PilotLost, {FailsafeAction::Kill, kPilotLostPersistenceMs}, KillSource::Failsafe},
    // daemon/bus/thruster_health: a thruster failed ThrusterHealth::kUnreachableAfter transfers.
    {FailsafeCondition::ThrusterUnreachable, {FailsafeAction::Kill, 0}, KillSource::Device},
    // daemon/recovery/bus_loss: recovery failed, or a lockup outlasted the command timeout.
    {FailsafeCondition::BusLost, {FailsafeAction::Kill, 0}, KillSource::Bus},
    // daemon/teensy/teensy_connection: the SPI device went, or the Teensy fell silent.
    {FailsafeCondition::TeensyLinkLost, {FailsafeAction::Kill, 0}, KillSource::Failsafe},
    // daemon/safety/safety_lines: the switch cannot be read (it counts as set meanwhile).
    {FailsafeCondition::KillSwitchUnreadable, {FailsafeAction::Kill, 0}, KillSource::Switch},
    // daemon/safety/safety_lines: the kill or power-off output cannot be written.
    {FailsafeCondition::SafetyLineLost, {FailsafeAction::Kill, 0}, KillSource::Device},
}};
constexpr const FailsafeRow& failsafe_row(FailsafeCondition c) { return kFailsafeTable[static_cast<std::size_t>(c)]; }
// A row per condition, in the enum's order.
static_assert([] {
    for (std::size_t i = 0; i < kFailsafeConditionCount; ++i)
        if (kFailsafeTable[i].condition != static_cast<FailsafeCondition>(i))
            return false;
    return true;
}());
// The FAULT bit of a thruster condition (SeaBotix IDS 8.4.2, word 2).
uint8_t condition_fault_bit(FailsafeCondition c);

// How a thruster condition ends, as the controller reports it (SeaBotix IDS 8.4.2 remarks):
// water detect, stall and hall when the bit reads clear; ground fault only when power is cycled
// (the controller keeps the bit until then, remark 3); overtemp sets at 110 C and clears at
// 100 C (remark 6), which the policy applies to the TEMPERATURE byte as well as the bit.
enum class FailsafeClearing { BitClear, PowerCycle, Hysteresis };
FailsafeClearing condition_clearing(FailsafeCondition c);

// [failsafe.surface]: the ascent (a heave demand on the mixing's z axis, +deeper, so
// negative is up) for a time, then a kill.
struct SurfaceSettings {
    double heave = -0.5;
    uint32_t duration_ms = 15000;
};

struct FailsafeSettings {
    std::array<FailsafeRule, kFailsafeConditionCount> rules = default_rules();
    SurfaceSettings surface;
    uint8_t overtemp_set_c = 110;   // SeaBotix IDS 8.4.2 remark 6
    uint8_t overtemp_clear_c = 100;

    const FailsafeRule& rule(FailsafeCondition c) const { return rules[static_cast<std::size_t>(c)]; }
    FailsafeRule& rule(FailsafeCondition c) { return rules[static_cast<std::size_t>(c)]; }
    static std::array<FailsafeRule, kFailsafeConditionCount> default_rules();
};

} // namespace caracara
