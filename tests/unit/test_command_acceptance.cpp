// CommandAcceptance, the one place a command that moves something is accepted: each command in
// each vehicle state is accepted or refused with its named error, decided in the order state,
// length, range, budget (a row that breaks two rules gets the earlier one's error). Run on the
// daemon's own objects over the fakes of the device seam (DaemonRig); a refused command leaves
// the commanding client as it was, an accepted one makes its client the commanding client.
#include "tests/unit/fakes/daemon_rig.hpp"

#include "core/budget.hpp"
#include "core/motor_demand.hpp"
#include "daemon/vehicle/command_acceptance.hpp"
#include "tests/catch.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

using namespace caracara;
using namespace caracara::test;

namespace {

enum class Given { Ready, Killed, Arming, PoweredOff, Surfacing };

constexpr std::string_view kPilot = ":1.7";
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One command as a pilot sends it; `reject`: the budget's "reject" policy instead of the rig's
// "scale". Returns the acceptance's verdict.
using Command = std::function<Result(CommandAcceptance&, const MotorDemand& scale, const MotorDemand& reject)>;

Command thrust(std::vector<int32_t> values, bool reject = false) {
    return [values, reject](CommandAcceptance& a, const MotorDemand& scale, const MotorDemand& rejecting) {
        return a.thrust(values, reject ? rejecting : scale, kPilot).result;
    };
}

Command motion(AxisDemand axes, bool reject = false) {
    return [axes, reject](CommandAcceptance& a, const MotorDemand& scale, const MotorDemand& rejecting) {
        return a.motion(axes, reject ? rejecting : scale, kPilot).result;
    };
}

// `range`: the caller's own verdict on its arguments (the motor test's thruster and limit).
Command motors(MotorValues values, Result range = {}) {
    return [values, range](CommandAcceptance& a, const MotorDemand& scale, const MotorDemand&) {
        return a.motors(values, scale, kPilot, range).result;
    };
}

// A Teensy command (wheels, a turn) with its codec's verdict on its arguments.
Command teensy_command(Result range) {
    return [range](CommandAcceptance& a, const MotorDemand&, const MotorDemand&) { return a.accept_command(kPilot, range); };
}

struct Row {
    const char* what;
    Given given;
    Command command;
    Status expected;
};

const std::vector<int32_t> kGood{1000, -1000, 500, 0, 0, 0, 0, -500};
const std::vector<int32_t> kFull(8, kMotorMax); // over every budget row: 8 running, limit 4200
const Result kWheelsTooFast{Status::OutOfRange, "Set Speed: wheel speed out of range"};
const Result kNoSuchThruster{Status::OutOfRange, "thruster 8 is outside 0..7"};

std::vector<int32_t> with(std::vector<int32_t> v, std::size_t i, int32_t value) {
    v[i] = value;
    return v;
}

// The vehicle as the row gives it.
void bring(DaemonRig& rig, Given g) {
    Vehicle& v = rig.vehicle();
    switch (g) {
    case Given::Ready: break;
    case Given::Killed: REQUIRE(v.kill(KillSource::DBus, "the test").ok()); break;
    case Given::Arming:
        REQUIRE(v.kill(KillSource::DBus, "the test").ok());
        REQUIRE(v.clear_kill().ok()); // arming until the loop's next tick, which does not run here
        break;
    case Given::PoweredOff: REQUIRE(v.power_off("power-off").ok()); break;
    case Given::Surfacing: REQUIRE(v.motors().surface(AxisDemand{0, 0, -0.3, 0, 0, 0}).ok()); break;
    }
}

} // namespace

TEST_CASE("each command in each state: accepted, or its named error in the order state, length, range, budget") {
    const std::vector<Row> rows{
        // Accepted.
        {"SetThrust, eight values in range", Given::Ready, thrust(kGood), Status::Ok},
        {"SetThrust at full on all eight, scaled to the budget", Given::Ready, thrust(kFull), Status::Ok},
        {"SetMotion", Given::Ready, motion({0, 0.5, 0, 0, 0, 0}), Status::Ok},
        {"a packet's motors", Given::Ready, motors({0, 0, 0, 0, 0, 800, 0, 0}), Status::Ok},
        {"the wheels", Given::Ready, teensy_command({}), Status::Ok},
        // 1. The state, before anything the command says.
        {"SetThrust, killed", Given::Killed, thrust(kGood), Status::Killed},
        {"SetThrust, arming", Given::Arming, thrust(kGood), Status::Arming},
        {"SetThrust, powered off", Given::PoweredOff, thrust(kGood), Status::PoweredOff},
        {"SetThrust, another client while a failsafe surfaces", Given::Surfacing, thrust(kGood), Status::Surfacing},
        {"7 values, killed", Given::Killed, thrust(std::vector<int32_t>(7, 100)), Status::Killed},
        {"7 values, surfacing", Given::Surfacing, thrust(std::vector<int32_t>(7, 100)), Status::Surfacing},
        {"8851, arming", Given::Arming, thrust(with(kGood, 3, 8851)), Status::Arming},
        {"SetMotion NaN, killed", Given::Killed, motion({kNaN, 0, 0, 0, 0, 0}), Status::Killed},
        {"SetMotion 1.5, powered off", Given::PoweredOff, motion({0, 1.5, 0, 0, 0, 0}), Status::PoweredOff},
        {"a packet's motors, surfacing", Given::Surfacing, motors({100, 0, 0, 0, 0, 0, 0, 0}), Status::Surfacing},
        {"over the budget (reject), killed", Given::Killed, thrust(kFull, true), Status::Killed},
        {"the wheels too fast, killed", Given::Killed, teensy_command(kWheelsTooFast), Status::Killed},
        {"a motor test of thruster 8, arming", Given::Arming, motors({}, kNoSuchThruster), Status::Arming},
        {"the wheels, surfacing", Given::Surfacing, teensy_command({}), Status::Surfacing},
        // 2. The length.
        {"7 values", Given::Ready, thrust(std::vector<int32_t>(7, 100)), Status::InvalidLength},
        {"9 values", Given::Ready, thrust(std::vector<int32_t>(9, 100)), Status::InvalidLength},
        {"no values", Given::Ready, thrust({}), Status::InvalidLength},
        {"7 values, one out of range", Given::Ready, thrust({9000, 0, 0, 0, 0, 0, 0}), Status::InvalidLength},
        // 3. The range.
        {"8851", Given::Ready, thrust(with(kGood, 3, 8851)), Status::OutOfRange},
        {"-8851", Given::Ready, thrust(with(kGood, 7, -8851)), Status::OutOfRange},
        {"int32 min", Given::Ready, thrust(with(kGood, 0, std::numeric_limits<int32_t>::min())), Status::OutOfRange},
        {"out of range and over the budget (reject)", Given::Ready, thrust(with(kFull, 2, 9000), true), Status::OutOfRange},
        {"SetMotion NaN", Given::Ready, motion({kNaN, 0, 0, 0, 0, 0}), Status::InvalidValue},
        {"SetMotion inf", Given::Ready, motion({0, 0, 0, std::numeric_limits<double>::infinity(), 0, 0}), Status::InvalidValue},
        {"SetMotion 1.5", Given::Ready, motion({0, 1.5, 0, 0, 0, 0}), Status::OutOfRange},
        {"SetMotion -1.0001", Given::Ready, motion({0, 0, 0, 0, -1.0001, 0}), Status::OutOfRange},
        {"a packet's motor at 9000", Given::Ready, motors({9000, 0, 0, 0, 0, 0, 0, 0}), Status::OutOfRange},
        {"the wheels too fast", Given::Ready, teensy_command(kWheelsTooFast), Status::OutOfRange},
        {"a motor test of thruster 8", Given::Ready, motors({}, kNoSuchThruster), Status::OutOfRange},
        {"a turn by NaN", Given::Ready, teensy_command({Status::InvalidValue, "not a finite angle"}), Status::InvalidValue},
        // 4. The budget.
        {"SetThrust over the budget (reject)", Given::Ready, thrust(kFull, true), Status::OverBudget},
        {"SetMotion over the budget (reject)", Given::Ready, motion({0, 1.0, 0, 0, 0, 0}, true), Status::OverBudget},
    };
    for (const Row& row : rows) {
        INFO(std::string(row.what) + " -> " + std::string(status_name(row.expected)));
        DaemonRig rig;
        rig.run_until_ready();
        bring(rig, row.given);
        const ThrustProfile& profile = rig.vehicle().readings().profile();
        const MotorDemand scale(BudgetPolicy::Scale, profile);
        const MotorDemand reject(BudgetPolicy::Reject, profile);
        const std::string controller = rig.vehicle().readings().controller_client();
        const Result r = row.command(rig.vehicle().acceptance(), scale, reject);
        CHECK(status_name(r.status) == status_name(row.expected));
        CHECK(r.ok() == r.message.empty()); // a refusal says why
        if (r.ok())
            CHECK(rig.vehicle().readings().controller_client() == kPilot);
        else
            CHECK(rig.vehicle().readings().controller_client() == controller);
    }
}

TEST_CASE("an accepted motor command carries what the demand takes: the values, the budget over them") {
    DaemonRig rig;
    rig.run_until_ready();
    const MotorDemand scale(BudgetPolicy::Scale, rig.vehicle().readings().profile());
    CommandAcceptance& a = rig.vehicle().acceptance();

    const MotorVerdict full = a.thrust(kFull, scale, kPilot);
    REQUIRE(full.ok());
    CHECK(full.wanted == MotorValues{8850, 8850, 8850, 8850, 8850, 8850, 8850, 8850});
    CHECK(full.budget.saturated);
    CHECK(full.budget.limit == budget_limit(8));
    CHECK_FALSE(full.mix_saturated);

    // Every axis at full: the mixing scales the demand down, and says so.
    const MotorVerdict mixed = a.motion({1, 1, 1, 1, 1, 1}, scale, kPilot);
    REQUIRE(mixed.ok());
    CHECK(mixed.mix_saturated);
}

TEST_CASE("the ascent: only the failsafe drives while it surfaces, and a kill ends that") {
    DaemonRig rig;
    rig.run_until_ready();
    const MotorDemand scale(BudgetPolicy::Scale, rig.vehicle().readings().profile());
    CommandAcceptance& a = rig.vehicle().acceptance();

    REQUIRE(a.ascent({0, 0, -0.3, 0, 0, 0}, scale).ok());
    CHECK(a.surfacing());
    CHECK(rig.vehicle().readings().controller_client() == CommandAcceptance::kFailsafeClient);
    CHECK(a.thrust(kGood, scale, kPilot).result.status == Status::Surfacing);
    CHECK(a.accept_command(kPilot, {}).status == Status::Surfacing);
    CHECK(a.ascent({0, 0, -0.3, 0, 0, 0}, scale).ok()); // kept up past the command timeout

    REQUIRE(rig.vehicle().kill(KillSource::DBus, "the test").ok());
    CHECK_FALSE(a.surfacing());
    CHECK(a.thrust(kGood, scale, kPilot).result.status == Status::Killed);
    // A refused ascent does not start surfacing.
    CHECK(a.ascent({0, 0, -0.3, 0, 0, 0}, scale).result.status == Status::Killed);
    CHECK_FALSE(a.surfacing());
}
