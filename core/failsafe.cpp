#include "core/failsafe.hpp"

namespace caracara {

namespace {
constexpr std::array<std::string_view, kFailsafeConditionCount> kConditionNames{
    "water-detect", "ground-fault", "overtemp", "stall", "hall", "pilot-lost",
    "thruster-unreachable", "bus-lost", "teensy-link-lost", "kill-switch-unreadable"};
constexpr std::array<std::string_view, 4> kActionNames{"warn", "exclude", "surface", "kill"};

// The enum value whose name is `name`: the names are in enum order.
template <typename E, std::size_t N>
std::optional<E> from_name(const std::array<std::string_view, N>& names, std::string_view name) {
    for (std::size_t i = 0; i < N; ++i)
        if (names[i] == name)
            return static_cast<E>(i);
    return std::nullopt;
}
} // namespace

std::string_view condition_name(FailsafeCondition c) { return kConditionNames[static_cast<std::size_t>(c)]; }

std::optional<FailsafeCondition> condition_from_name(std::string_view name) {
    return from_name<FailsafeCondition>(kConditionNames, name);
}

std::string_view action_name(FailsafeAction a) { return kActionNames[static_cast<std::size_t>(a)]; }

std::optional<FailsafeAction> action_from_name(std::string_view name) {
    return from_name<FailsafeAction>(kActionNames, name);
}

uint8_t condition_fault_bit(FailsafeCondition c) {
    switch (c) {
    case FailsafeCondition::Overtemp: return 1u << 0;
    case FailsafeCondition::Stall: return 1u << 1;
    case FailsafeCondition::Hall: return 1u << 2;
    case FailsafeCondition::GroundFault: return 1u << 3;
    case FailsafeCondition::WaterDetect: return 1u << 4;
    default: return 0;
    }
}

FailsafeClearing condition_clearing(FailsafeCondition c) {
    switch (c) {
    case FailsafeCondition::GroundFault: return FailsafeClearing::PowerCycle;
    case FailsafeCondition::Overtemp: return FailsafeClearing::Hysteresis;
    default: return FailsafeClearing::BitClear;
    }
}

std::array<FailsafeRule, kFailsafeConditionCount> FailsafeSettings::default_rules() {
    // Why each, for a slightly buoyant vehicle: daemon/caracarad.toml.example.
    std::array<FailsafeRule, kFailsafeConditionCount> r{};
    r[static_cast<std::size_t>(FailsafeCondition::WaterDetect)] = {FailsafeAction::Surface, 2000};
    r[static_cast<std::size_t>(FailsafeCondition::GroundFault)] = {FailsafeAction::Exclude, 500};
    r[static_cast<std::size_t>(FailsafeCondition::Overtemp)] = {FailsafeAction::Exclude, 2000};
    r[static_cast<std::size_t>(FailsafeCondition::Stall)] = {FailsafeAction::Exclude, 1000};
    r[static_cast<std::size_t>(FailsafeCondition::Hall)] = {FailsafeAction::Exclude, 1000};
    for (std::size_t i = static_cast<std::size_t>(FailsafeCondition::PilotLost); i < kFailsafeConditionCount; ++i)
        r[i] = {FailsafeAction::Kill, 0};
    // The only fixed one with a persistence of its own: the lost pilot's thrust is already zero.
    r[static_cast<std::size_t>(FailsafeCondition::PilotLost)].persistence_ms = kPilotLostPersistenceMs;
    return r;
}

} // namespace caracara
