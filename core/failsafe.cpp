#include "core/failsafe.hpp"

namespace caracara {

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
