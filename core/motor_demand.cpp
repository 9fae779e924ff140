#include "core/motor_demand.hpp"

#include <cmath>

namespace caracara {

MotorValues MotorDemand::scaled(const MotorValues& wanted) const {
    // The profile scales before the budget, so the budget holds whatever the profile.
    MotorValues m{};
    for (size_t i = 0; i < kMotorCount; ++i)
        m[i] = excluded_[i] ? 0 : static_cast<int32_t>(std::lround(wanted[i] * profile_->factor));
    return m;
}

bool MotorDemand::take(const MotorValues& wanted, const BudgetResult& b, bool mix_saturated) {
    const int32_t limit = b.running ? b.limit : 0;
    const bool saturated = b.saturated || mix_saturated;
    const bool changed = requested_ != wanted || applied_ != b.motors || limit_ != limit || saturated_ != saturated;
    requested_ = wanted;
    applied_ = b.motors;
    limit_ = limit;
    saturated_ = saturated;
    mix_saturated_ = mix_saturated;
    return changed;
}

bool MotorDemand::set_profile(const ThrustProfile& profile) {
    profile_ = &profile;
    return reapply();
}

bool MotorDemand::set_excluded(const std::array<bool, kMotorCount>& excluded) {
    excluded_ = excluded;
    return reapply();
}

bool MotorDemand::reapply() {
    BudgetResult b = evaluate(requested_);
    if (!b.ok()) // under policy "reject" a command that no longer fits goes to zero, not the old factor
        b = apply_budget(MotorValues{}, policy_);
    return take(requested_, b, mix_saturated_);
}

void MotorDemand::clear() {
    requested_.fill(0);
    applied_.fill(0);
    limit_ = 0;
    saturated_ = false;
    mix_saturated_ = false;
}

} // namespace caracara
