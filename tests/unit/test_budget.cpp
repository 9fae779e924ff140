#include "core/budget.hpp"

#include "tests/catch.hpp"
#include <cstdlib>
#include <limits>

using namespace caracara;

namespace {

int32_t peak_of(const MotorValues& m) {
    int32_t p = 0;
    for (int32_t v : m)
        p = std::max(p, std::abs(v));
    return p;
}

bool same_direction(const MotorValues& in, const MotorValues& out) {
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        if (out[i] != 0 && (out[i] > 0) != (in[i] > 0))
            return false;
        if (std::abs(out[i]) > std::abs(in[i]))
            return false;
    }
    return true;
}

// The seed's table, with counts between its rows taking the stricter row.
int32_t expected_limit(int running) {
    if (running == 0)
        return kMotorMax;
    if (running <= 2)
        return 7850;
    if (running <= 4)
        return 5750;
    return 4200;
}

// First `running` motors at full scale with alternating signs.
MotorValues full(int running) {
    MotorValues m{};
    for (int i = 0; i < running; ++i)
        m[static_cast<std::size_t>(i)] = (i % 2 == 0) ? kMotorMax : -kMotorMax;
    return m;
}

} // namespace

TEST_CASE("the limit follows the seed's table for every count of running motors") {
    CHECK(budget_limit(0) == kMotorMax);
    CHECK(budget_limit(1) == 7850);
    CHECK(budget_limit(2) == 7850);
    CHECK(budget_limit(3) == 5750);
    CHECK(budget_limit(4) == 5750);
    for (int n = 5; n <= 8; ++n)
        CHECK(budget_limit(n) == 4200);
}

TEST_CASE("running motors are the non-zero values") {
    CHECK(running_motors(MotorValues{}) == 0);
    CHECK(running_motors(MotorValues{1, 0, -1, 0, 0, 0, 0, 8850}) == 3);
    CHECK(running_motors(full(8)) == 8);
}

TEST_CASE("scale policy holds every count of running motors to its limit, keeping direction") {
    for (int n = 1; n <= 8; ++n) {
        INFO(n << " running motors");
        const MotorValues in = full(n);
        const BudgetResult r = apply_budget(in, BudgetPolicy::Scale);
        REQUIRE(r.ok());
        CHECK(r.saturated);
        CHECK(r.limit == expected_limit(n));
        CHECK(r.running == n);
        CHECK(peak_of(r.motors) == expected_limit(n));  // the largest motor gets the whole limit
        CHECK(peak_of(r.motors) <= budget_limit(running_motors(r.motors)));
        CHECK(same_direction(in, r.motors));
        for (int i = 0; i < n; ++i)
            CHECK(std::abs(r.motors[static_cast<std::size_t>(i)]) == expected_limit(n));
        CHECK_THAT(r.message, Catch::Contains(std::to_string(expected_limit(n))));
    }
}

TEST_CASE("values within the budget pass unchanged") {
    for (int n = 1; n <= 8; ++n) {
        INFO(n << " running motors");
        MotorValues in{};
        for (int i = 0; i < n; ++i)
            in[static_cast<std::size_t>(i)] = (i % 2 == 0) ? expected_limit(n) : -expected_limit(n);
        for (BudgetPolicy p : {BudgetPolicy::Scale, BudgetPolicy::Reject}) {
            const BudgetResult r = apply_budget(in, p);
            REQUIRE(r.ok());
            CHECK_FALSE(r.saturated);
            CHECK(r.motors == in);
            CHECK(r.limit == expected_limit(n));
        }
    }
    const BudgetResult idle = apply_budget(MotorValues{});
    CHECK(idle.ok());
    CHECK(idle.running == 0);
    CHECK_FALSE(idle.saturated);
}

TEST_CASE("scaling keeps the ratios between motors (never clips one by one)") {
    // 8 running -> 4200. Clipping would give 4200, 4200, -2000, ... and turn the vehicle.
    const MotorValues in{8850, 6000, -2000, 100, -8850, 4425, 1, -3};
    const BudgetResult r = apply_budget(in);
    REQUIRE(r.ok());
    CHECK(r.saturated);
    CHECK(r.limit == 4200);
    CHECK(r.motor == 0);
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        INFO("motor " << i);
        const double exact = static_cast<double>(in[i]) * 4200.0 / 8850.0;
        CHECK(std::abs(static_cast<double>(r.motors[i]) - exact) < 1.0);  // rounded toward zero
        CHECK(std::abs(r.motors[i]) <= std::abs(exact) + 1e-9);
    }
    CHECK(r.motors[0] == 4200);
    CHECK(r.motors[4] == -4200);
    CHECK(same_direction(in, r.motors));
}

TEST_CASE("scaling may round a small motor to zero; the result still complies with the final count") {
    // 5 running -> 4200; the 1 becomes 0 (4 running, limit 5750): still within both.
    const MotorValues in{8850, 8850, -8850, 8850, 1, 0, 0, 0};
    const BudgetResult r = apply_budget(in);
    REQUIRE(r.ok());
    CHECK(r.saturated);
    CHECK(r.limit == 4200);
    CHECK(r.motors == MotorValues{4200, 4200, -4200, 4200, 0, 0, 0, 0});
    CHECK(r.running == 4);
    CHECK(peak_of(r.motors) <= budget_limit(r.running));
}

TEST_CASE("scale policy never exceeds the limit over a sweep of inputs") {
    uint32_t seed = 12345;
    auto next = [&seed]() {
        seed = seed * 1664525u + 1013904223u;
        return seed >> 8;
    };
    for (int k = 0; k < 20000; ++k) {
        MotorValues in{};
        for (auto& v : in) {
            const uint32_t pick = next() % 4;
            v = pick == 0 ? 0 : static_cast<int32_t>(next() % (2 * kMotorMax + 1)) - kMotorMax;
        }
        const BudgetResult r = apply_budget(in);
        REQUIRE(r.ok());
        REQUIRE(peak_of(r.motors) <= budget_limit(running_motors(r.motors)));
        REQUIRE(peak_of(r.motors) <= r.limit);
        REQUIRE(same_direction(in, r.motors));
        REQUIRE(r.saturated == (peak_of(in) > budget_limit(running_motors(in))));
        if (!r.saturated)
            REQUIRE(r.motors == in);
    }
}

TEST_CASE("reject policy refuses an over-budget set for every count and changes nothing") {
    for (int n = 1; n <= 8; ++n) {
        INFO(n << " running motors");
        // Every motor at its limit and motor 0 one over: enough to refuse.
        MotorValues in{};
        for (int i = 0; i < n; ++i)
            in[static_cast<std::size_t>(i)] = (i % 2 == 0) ? expected_limit(n) : -expected_limit(n);
        in[0] = expected_limit(n) + 1;
        const BudgetResult r = apply_budget(in, BudgetPolicy::Reject);
        CHECK(r.error == BudgetError::OverBudget);
        CHECK(error_name(r.error) == "OverBudget");
        CHECK(r.motors == in);
        CHECK_FALSE(r.saturated);
        CHECK(r.limit == expected_limit(n));
        CHECK(r.running == n);
        CHECK(r.motor == 0);
        CHECK_THAT(r.message, Catch::Contains(std::to_string(expected_limit(n))) &&
                                  Catch::Contains(std::to_string(n) + " running motors"));
    }
}

TEST_CASE("values outside -8850..8850 are refused under either policy, naming the motor") {
    for (BudgetPolicy p : {BudgetPolicy::Scale, BudgetPolicy::Reject}) {
        for (int32_t bad : {kMotorMax + 1, -kMotorMax - 1, std::numeric_limits<int32_t>::min(),
                            std::numeric_limits<int32_t>::max()}) {
            for (std::size_t i = 0; i < kMotorCount; ++i) {
                MotorValues in{};
                in[i] = bad;
                const BudgetResult r = apply_budget(in, p);
                CHECK(r.error == BudgetError::OutOfRange);
                CHECK(error_name(r.error) == "OutOfRange");
                CHECK(r.motor == static_cast<int>(i));
                CHECK(r.motors == in);
                CHECK_THAT(r.message, Catch::Contains("motor " + std::to_string(i)));
            }
        }
    }
    CHECK(policy_name(BudgetPolicy::Scale) == "scale");
    CHECK(policy_name(BudgetPolicy::Reject) == "reject");
}
