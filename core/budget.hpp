// The electrical current budget from the Caracara packet seed: the more motors run, the
// lower each one's absolute maximum, or the vehicle risks an electrical failure.
//
//   motors running (value != 0)   |value| limit
//   0                             none needed (kMotorMax, the full range)
//   1-2                           7850
//   3-4                           5750
//   5-8                           4200
// The seed lists 2, 4 and 8 motors; counts between its rows take the stricter row.
#pragma once

#include "core/enum_names.hpp"
#include "core/mixing.hpp"

#include <string>
#include <string_view>

namespace caracara {

enum class BudgetPolicy {
    Scale,   // scale all motors by one factor so the largest fits (default)
    Reject,  // refuse the command with OverBudget and change nothing
};
template <>
struct EnumNames<BudgetPolicy> {
    static constexpr std::array<EnumName<BudgetPolicy>, 2> table{{
        {BudgetPolicy::Scale, "scale"},
        {BudgetPolicy::Reject, "reject"},
    }};
};
inline std::string_view policy_name(BudgetPolicy p) { return name_of(p); }

enum class BudgetError {
    None,
    OutOfRange,  // a motor value outside -kMotorMax..kMotorMax
    OverBudget,  // Reject policy: the largest |value| exceeds the limit for the count
};
template <>
struct EnumNames<BudgetError> {
    static constexpr std::array<EnumName<BudgetError>, 3> table{{
        {BudgetError::None, "None"},
        {BudgetError::OutOfRange, "OutOfRange"},
        {BudgetError::OverBudget, "OverBudget"},
    }};
};
inline std::string_view error_name(BudgetError v) { return name_of(v); }

int running_motors(const MotorValues& motors);  // number of non-zero values
int32_t budget_limit(int running);              // see the table above; 0 -> kMotorMax

struct BudgetResult {
    BudgetError error = BudgetError::None;
    int motor = -1;          // OutOfRange: the bad motor; OverBudget/saturated: the largest
    MotorValues motors{};    // the values to send; on error, the input unchanged
    bool saturated = false;  // Scale policy scaled the values down
    int32_t limit = kMotorMax;  // the limit the returned values were held to
    int running = 0;         // motors running in the returned values
    std::string message;     // human-readable, names the motor and the numbers
    bool ok() const { return error == BudgetError::None; }
};

// Validates each value, then holds the set to the budget under the given policy.
// Scale rounds toward zero so the limit is never exceeded; that can round a small motor
// to 0, which lowers the count and only loosens the limit, so the result still complies
// (it is re-checked against the final count).
BudgetResult apply_budget(const MotorValues& motors, BudgetPolicy policy = BudgetPolicy::Scale);

} // namespace caracara
