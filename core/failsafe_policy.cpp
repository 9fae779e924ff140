#include "core/failsafe_policy.hpp"

#include <algorithm>

namespace caracara {

FailsafePolicy::FailsafePolicy(const FailsafeSettings& settings, std::size_t thrusters)
    : settings_(settings), rows_(thrusters + 1) {}

FailsafePolicy::Tracked& FailsafePolicy::tracked(int thruster, FailsafeCondition c) {
    const std::size_t row = thruster < 0 ? rows_.size() - 1 : static_cast<std::size_t>(thruster);
    return rows_[row][static_cast<std::size_t>(c)];
}

bool FailsafePolicy::overtemp(const Tracked& t, uint8_t bits, std::optional<uint8_t> temperature_c) const {
    // SeaBotix IDS 8.4.2 remark 6: set at 110 C, clear at 100 C. The bit is the controller's
    // word; the temperature holds a failsafe that tripped until it is down to 100 C.
    if (bits & condition_fault_bit(FailsafeCondition::Overtemp))
        return true;
    if (!temperature_c)
        return false;
    return *temperature_c >= settings_.overtemp_set_c || (t.present && *temperature_c > settings_.overtemp_clear_c);
}

FailsafeTransitions FailsafePolicy::observe(std::size_t thruster, uint8_t fault_bits,
                                            std::optional<uint8_t> temperature_c, uint64_t now) {
    FailsafeTransitions out;
    if (thruster + 1 >= rows_.size())
        return out;
    const int i = static_cast<int>(thruster);
    for (FailsafeCondition c : kThrusterConditions) {
        const Tracked& t = tracked(i, c);
        // Ground fault: the controller keeps the bit until its power is cycled (IDS 8.4.2
        // remark 3), so "the bit reads clear" is that power cycle.
        const bool present = condition_clearing(c) == FailsafeClearing::Hysteresis
                                 ? overtemp(t, fault_bits, temperature_c)
                                 : (fault_bits & condition_fault_bit(c)) != 0;
        update(i, c, present, now, out);
    }
    return out;
}

FailsafeTransitions FailsafePolicy::set_condition(FailsafeCondition c, bool holds, uint64_t now) {
    FailsafeTransitions out;
    update(-1, c, holds, now, out);
    return out;
}

void FailsafePolicy::update(int thruster, FailsafeCondition c, bool present, uint64_t now, FailsafeTransitions& out) {
    Tracked& t = tracked(thruster, c);
    if (present && !t.present) {
        t.present = true;
        t.since = now;
    }
    if (!present && t.present) {
        t.present = false;
        if (t.active) {
            t.active = false;
            auto it = std::find_if(active_.begin(), active_.end(), [&](const ActiveFailsafe& a) {
                return a.condition == c && a.thruster == thruster;
            });
            if (it != active_.end()) {
                out.push_back({*it, false});
                active_.erase(it);
            }
        }
        return;
    }
    if (t.present && !t.active && now - t.since >= uint64_t(settings_.rule(c).persistence_ms) * 1'000'000ull) {
        t.active = true;
        const ActiveFailsafe a{c, settings_.rule(c).action, thruster, false};
        active_.push_back(a);
        out.push_back({a, true});
    }
}

FailsafeTransitions FailsafePolicy::tick(uint64_t now) {
    FailsafeTransitions out;
    for (std::size_t row = 0; row < rows_.size(); ++row)
        for (std::size_t c = 0; c < kFailsafeConditionCount; ++c)
            if (rows_[row][c].present && !rows_[row][c].active)
                update(row + 1 == rows_.size() ? -1 : static_cast<int>(row), static_cast<FailsafeCondition>(c), true,
                       now, out);
    return out;
}

uint64_t FailsafePolicy::next_deadline() const {
    uint64_t at = kNoDeadline;
    for (const auto& row : rows_)
        for (std::size_t c = 0; c < kFailsafeConditionCount; ++c)
            if (row[c].present && !row[c].active)
                at = std::min<uint64_t>(at, row[c].since + uint64_t(settings_.rules[c].persistence_ms) * 1000000);
    return at;
}

uint64_t FailsafePolicy::pending_deadline(FailsafeCondition c) const {
    const Tracked& t = rows_.back()[static_cast<std::size_t>(c)];
    return t.present && !t.active ? t.since + uint64_t(settings_.rule(c).persistence_ms) * 1'000'000ull : kNoDeadline;
}

std::optional<FailsafeAction> FailsafePolicy::strongest() const {
    std::optional<FailsafeAction> s;
    for (const ActiveFailsafe& a : active_)
        if (!s || a.effective() > *s)
            s = a.effective();
    return s;
}

bool FailsafePolicy::excluded(std::size_t thruster) const {
    return std::any_of(active_.begin(), active_.end(), [&](const ActiveFailsafe& a) {
        return a.thruster == static_cast<int>(thruster) && a.effective() == FailsafeAction::Exclude;
    });
}

std::vector<ActiveFailsafe> FailsafePolicy::blocking() const {
    std::vector<ActiveFailsafe> out;
    for (const ActiveFailsafe& a : active_)
        if (a.effective() >= FailsafeAction::Surface)
            out.push_back(a);
    return out;
}

std::size_t FailsafePolicy::override_condition(FailsafeCondition c) {
    std::size_t n = 0;
    for (ActiveFailsafe& a : active_)
        if (a.condition == c && !a.overridden && a.action >= FailsafeAction::Surface) {
            a.overridden = true;
            ++n;
        }
    return n;
}

} // namespace caracara
