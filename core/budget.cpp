#include "core/budget.hpp"

#include <cstdlib>

namespace caracara {

int running_motors(const MotorValues& motors) {
    int n = 0;
    for (int32_t v : motors)
        n += v != 0 ? 1 : 0;
    return n;
}

int32_t budget_limit(int running) {
    if (running <= 0)
        return kMotorMax;
    if (running <= 2)
        return 7850;
    if (running <= 4)
        return 5750;
    return 4200;
}

namespace {
// |v| without overflow concerns: values are validated to +-kMotorMax before use.
int32_t magnitude(int32_t v) { return v < 0 ? -v : v; }

bool complies(const MotorValues& m) {
    const int32_t limit = budget_limit(running_motors(m));
    for (int32_t v : m)
        if (magnitude(v) > limit)
            return false;
    return true;
}
} // namespace

BudgetResult apply_budget(const MotorValues& motors, BudgetPolicy policy) {
    BudgetResult r;
    r.motors = motors;
    r.running = running_motors(motors);
    r.limit = budget_limit(r.running);

    for (std::size_t i = 0; i < kMotorCount; ++i) {
        const int32_t v = motors[i];
        if (v < -kMotorMax || v > kMotorMax) {
            r.error = BudgetError::OutOfRange;
            r.motor = static_cast<int>(i);
            r.message = "motor " + std::to_string(i) + ": " + std::to_string(v) + " is outside -" +
                        std::to_string(kMotorMax) + ".." + std::to_string(kMotorMax);
            return r;
        }
    }

    int32_t peak = 0;
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        if (magnitude(motors[i]) > peak) {
            peak = magnitude(motors[i]);
            r.motor = static_cast<int>(i);
        }
    }
    if (peak <= r.limit) {
        r.motor = -1;
        return r;
    }

    if (policy == BudgetPolicy::Reject) {
        r.error = BudgetError::OverBudget;
        r.message = "motor " + std::to_string(r.motor) + ": |" + std::to_string(motors[static_cast<std::size_t>(r.motor)]) +
                    "| exceeds the limit of " + std::to_string(r.limit) + " for " + std::to_string(r.running) +
                    " running motors";
        return r;
    }

    // One factor limit/peak for every motor keeps the ratios, hence the direction of motion;
    // integer division truncates toward zero, so no motor ends up above the limit.
    MotorValues scaled{};
    for (std::size_t i = 0; i < kMotorCount; ++i)
        scaled[i] = static_cast<int32_t>(int64_t{motors[i]} * r.limit / peak);
    // Truncation may have zeroed a small motor: the count can only drop, the limit only
    // loosen, so this holds; checked rather than assumed because it is the safety promise.
    if (!complies(scaled))
        scaled = MotorValues{};
    r.motors = scaled;
    r.running = running_motors(scaled);
    r.saturated = true;
    r.message = "scaled by " + std::to_string(r.limit) + "/" + std::to_string(peak) + " to hold " +
                std::to_string(running_motors(motors)) + " running motors to " + std::to_string(r.limit);
    return r;
}

} // namespace caracara
