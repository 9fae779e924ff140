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
    std::array<FailsafeRule, kFailsafeConditionCount> r{};
    for (const FailsafeRow& row : kFailsafeTable)
        r[static_cast<std::size_t>(row.condition)] = row.default_rule;
    return r;
}

} // namespace caracara
