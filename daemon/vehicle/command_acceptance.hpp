// The one place a command that moves something is accepted: SetThrust, SetMotion, a packet's
// motors, a motor test, direction detection's pulses, the failsafe's ascent (for MotorCommands)
// and the Teensy's wheels and turns (CommandGate). Each is decided in one order, and the first
// refusal is the caller's error, with nothing changed:
//   1. the vehicle's state: Surfacing while a failsafe's ascent runs (but for the ascent
//      itself), else VehicleCondition::state_error (BusLost, Arming, Killed, PoweredOff);
//   2. the length: InvalidLength (SetThrust's eight values);
//   3. the range: the caller's own verdict first (the motor test's thruster and limit, the
//      Teensy's codec: wheel speeds, a turn's angle), then OutOfRange (a motor outside
//      -8850..8850, a mixed demand outside -1..1) or InvalidValue (a demand that is not a
//      finite number);
//   4. the budget: OverBudget (core/budget under the thrust profile, policy "reject").
// An accepted command makes its client the commanding client with the safety machine, restarts
// the command timeout, announces a new controller and ends pilot-lost (PilotWatch). What the
// motors then become is MotorCommands' job. Owned by Vehicle.
#pragma once

#include "core/budget.hpp"
#include "core/mixing.hpp"
#include "core/motor.hpp"
#include "core/motor_demand.hpp"
#include "core/safety.hpp"
#include "core/status.hpp"
#include "daemon/interfaces/command_gate.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "daemon/loop/deadline_timer.hpp"
#include "daemon/vehicle/pilot_watch.hpp"
#include "daemon/vehicle/vehicle_condition.hpp"

#include <cstdint>
#include <span>
#include <string_view>

namespace caracara {

// A motor command as decided: refused (`result`), or accepted with what MotorDemand::take needs.
struct MotorVerdict {
    Result result;
    MotorValues wanted{};       // the command's values, before the thrust profile
    BudgetResult budget;        // the budget over them under the profile
    bool mix_saturated = false; // the mixing scaled the demand down
    bool ok() const { return result.ok(); }
};

class CommandAcceptance final : public CommandGate {
public:
    static constexpr std::string_view kFailsafeClient = "failsafe"; // who drives an ascent

    // `mixing`: SetMotion's matrix ([mixing]); `pilots`: told when a command came (pilot-lost ends).
    CommandAcceptance(const MixMatrix& mixing, SafetyMachine& safety, const VehicleCondition& condition,
                      DeadlineTimer& deadline, VehicleEvents& events, PilotWatch& pilots)
        : mixing_(mixing), safety_(safety), condition_(condition), deadline_(deadline), events_(events),
          pilots_(pilots) {}

    // Each budgets under `demand` (its profile, policy and exclusions) without changing it.
    MotorVerdict thrust(std::span<const int32_t> values, const MotorDemand& demand, std::string_view client);
    MotorVerdict motion(const AxisDemand& axes, const MotorDemand& demand, std::string_view client);
    // Eight motor values already in their shape (a packet's, a motor test's, a pulse), with the
    // caller's own verdict on its arguments (`range`: the motor test's thruster and limit).
    MotorVerdict motors(const MotorValues& values, const MotorDemand& demand, std::string_view client,
                        const Result& range = {});
    // The failsafe's ascent, as client kFailsafeClient (again to keep it past the command
    // timeout); once accepted, every other client gets Surfacing until a kill ends it.
    MotorVerdict ascent(const AxisDemand& axes, const MotorDemand& demand);
    bool surfacing() const { return surfacing_; }
    void end_surfacing() { surfacing_ = false; }

    // CommandGate: the Teensy's wheels and turns, with their codec's verdict as `range`.
    Result state_error() const override { return condition_.state_error(); }
    bool powered_off() const override { return safety_.state() == SafetyState::PoweredOff; }
    Result accept_command(std::string_view client, const Result& range) override;

private:
    Result state(std::string_view client) const;
    // Range, budget, then taken (take).
    MotorVerdict within_range_and_budget(const MotorValues& wanted, bool mix_saturated, const MotorDemand& demand,
                                         std::string_view client);
    Result take(std::string_view client);

    const MixMatrix& mixing_;
    SafetyMachine& safety_;
    const VehicleCondition& condition_;
    DeadlineTimer& deadline_;
    VehicleEvents& events_;
    PilotWatch& pilots_;
    bool surfacing_ = false;
};

} // namespace caracara
