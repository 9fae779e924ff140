// The motor demand: profile before budget, announcements only on change, a profile switch.
#include "core/motor_demand.hpp"

#include "tests/catch.hpp"

using namespace caracara;

TEST_CASE("the profile scales before the budget, and the budget still holds") {
    const ThrustProfile water{"water", 1.0}, half{"half", 0.5};
    MotorDemand d(BudgetPolicy::Scale, water);
    const MotorValues full{8850, 8850, 8850, 8850, 8850, 0, 0, 0};
    BudgetResult b = d.evaluate(full);
    REQUIRE(b.ok());
    CHECK(d.take(full, b, false));
    CHECK(d.applied()[0] == 4200); // five motors: 4200 each
    CHECK(d.saturated());
    CHECK(d.requested() == full);
    CHECK_FALSE(d.set_profile(half)); // 4425 each: still held at 4200, nothing announced changes
    CHECK(d.applied()[0] == 4200);
    CHECK(d.saturated());
    const ThrustProfile air{"air", 0.15};
    CHECK(d.set_profile(air));
    CHECK(d.applied()[0] == 1328); // round(8850 * 0.15)
    CHECK_FALSE(d.saturated());
    CHECK(d.requested() == full);  // what was asked is kept
}

TEST_CASE("the same command again changes nothing worth announcing") {
    const ThrustProfile water{"water", 1.0};
    MotorDemand d(BudgetPolicy::Scale, water);
    const MotorValues m{1000, 0, 0, 0, 0, 0, 0, 0};
    CHECK(d.take(m, d.evaluate(m), false));
    CHECK_FALSE(d.take(m, d.evaluate(m), false));
    d.clear();
    CHECK(d.applied() == MotorValues{});
    CHECK(d.limit() == 0);
}

TEST_CASE("under policy reject a command that no longer fits a new profile goes to zero") {
    const ThrustProfile low{"low", 0.4}, water{"water", 1.0};
    MotorDemand d(BudgetPolicy::Reject, low);
    const MotorValues m{8850, 8850, 8850, 8850, 8850, 0, 0, 0}; // 3540 each under 0.4: fits
    BudgetResult b = d.evaluate(m);
    REQUIRE(b.ok());
    d.take(m, b, false);
    CHECK(d.applied()[0] == 3540);
    CHECK(d.set_profile(water)); // 8850 x5 is over budget: refused, so zero rather than 0.4
    CHECK(d.applied() == MotorValues{});
}

TEST_CASE("an excluded thruster is ordered zero and left out of the budget's count") {
    const ThrustProfile water{"water", 1.0};
    MotorDemand d(BudgetPolicy::Scale, water);
    const MotorValues m{7000, 7000, 7000, 0, 0, 0, 0, 0};
    CHECK(d.take(m, d.evaluate(m), false));
    CHECK(d.applied() == MotorValues{5750, 5750, 5750, 0, 0, 0, 0, 0}); // three running
    std::array<bool, kMotorCount> out{};
    out[2] = true;
    CHECK(d.set_excluded(out));
    CHECK(d.applied() == MotorValues{7000, 7000, 0, 0, 0, 0, 0, 0}); // two running: 7850 allows 7000
    CHECK(d.limit() == 7850);
    CHECK(d.requested() == m);
    // A new command while excluded stays without it; lifting the exclusion brings it back.
    const MotorValues n{0, 0, 3000, 3000, 0, 0, 0, 0};
    CHECK(d.take(n, d.evaluate(n), false));
    CHECK(d.applied() == MotorValues{0, 0, 0, 3000, 0, 0, 0, 0});
    CHECK(d.set_excluded({}));
    CHECK(d.applied() == n);
    // Cleared (a kill) keeps nothing, but the exclusion stays for the next command.
    CHECK(d.set_excluded(out));
    d.clear();
    CHECK(d.take(m, d.evaluate(m), false));
    CHECK(d.applied()[2] == 0);
}
