// What the thrusters are asked for: the last accepted command (requested), scaled by the thrust
// profile and held to the current budget (applied), with the budget's limit and whether
// anything saturated. Pure: the Vehicle decides when a command is accepted, this decides what
// it becomes.
#pragma once

#include "core/budget.hpp"
#include "core/config.hpp"
#include "core/motor.hpp"

#include <array>
#include <cstdint>

namespace caracara {

class MotorDemand {
public:
    MotorDemand(BudgetPolicy policy, const ThrustProfile& profile) : policy_(policy), profile_(&profile) {}

    // The budget over `wanted` under the current profile, without taking it: the caller checks
    // the result (range, OverBudget) before it accepts the command.
    BudgetResult evaluate(const MotorValues& wanted) const { return apply_budget(scaled(wanted), policy_); }
    // Takes a command evaluated above; true when what is announced (values, limit, saturation)
    // changed.
    bool take(const MotorValues& wanted, const BudgetResult& b, bool mix_saturated);
    // A new profile: the standing command under it (zero if it no longer fits a "reject" budget).
    bool set_profile(const ThrustProfile& profile);
    // Thrusters a failsafe excluded: ordered zero and so left out of the budget's count; the
    // standing command goes out again without them (and with them once they are back).
    bool set_excluded(const std::array<bool, kMotorCount>& excluded);
    // Kill, timeout, client gone: nothing stored resumes by itself.
    void clear();

    const MotorValues& requested() const { return requested_; }
    const MotorValues& applied() const { return applied_; }
    int32_t limit() const { return limit_; }
    bool saturated() const { return saturated_; }
    const ThrustProfile& profile() const { return *profile_; }
    const std::array<bool, kMotorCount>& excluded() const { return excluded_; }

private:
    bool reapply(); // the standing command again under the current profile and exclusions
    MotorValues scaled(const MotorValues& wanted) const;

    BudgetPolicy policy_;
    const ThrustProfile* profile_;
    MotorValues requested_{};
    // Kept: where the order is decided (profile, budget, exclusions); MotorValues reads it, the loop takes it.
    MotorValues applied_{};
    int32_t limit_ = 0;
    bool saturated_ = false;
    bool mix_saturated_ = false;
    std::array<bool, kMotorCount> excluded_{};
};

} // namespace caracara
