// The motor commands (SetThrust, SetMotion, SetProfile, and the failsafes' exclusion and
// ascent): checked, scaled by the profile and held to the budget (MotorDemand), taken as the
// command standing now once the vehicle's state allows (CommandGate, the safety machine), and
// handed down to the thrusters through the SafetyActuator. Owned by Vehicle.
#pragma once

#include "core/config.hpp"
#include "core/mixing.hpp"
#include "core/motor_demand.hpp"
#include "core/safety.hpp"
#include "core/status.hpp"
#include "daemon/safety/safety_actuator.hpp"
#include "daemon/interfaces/command_gate.hpp"
#include "daemon/interfaces/vehicle_events.hpp"

#include <array>
#include <cstdint>
#include <span>
#include <string_view>

namespace caracara {

class MotorCommands final {
public:
    static constexpr std::string_view kFailsafeClient = "failsafe"; // who drives an ascent

    // `gate`: the vehicle, where a command is accepted (CommandGate::accept_command).
    MotorCommands(const DaemonConfig& config, const SafetyMachine& safety, CommandGate& gate,
                  SafetyActuator& actuator, VehicleEvents& events);

    Result set_thrust(std::span<const int32_t> values, std::string_view client);
    Result set_motion(const AxisDemand& demand, std::string_view client);
    // Selects a thrust profile by name; the current command goes out again under it at once.
    Result set_profile(std::string_view name);
    // Through the budget, then accepted (CommandGate::accept_command); then handed down.
    Result accept(const MotorValues& wanted, bool mix_saturated, std::string_view client);
    // These thrusters to zero and out of the budget's count; the standing command goes on.
    void exclude(const std::array<bool, kMotorCount>& excluded);
    // The ascent, through the mixing and the budget, as client kFailsafeClient (called again
    // to keep it past the command timeout); every other motion command gets Surfacing until
    // a kill ends it (end_surfacing).
    Result surface(const AxisDemand& ascent);
    bool surfacing() const { return surfacing_; }
    void end_surfacing() { surfacing_ = false; }
    void clear() { demand_.clear(); }

    // What thruster i is to be ordered now: its applied value while the vehicle may drive.
    int32_t order_value(size_t i) const { return safety_.may_drive() ? demand_.applied()[i] : 0; }
    const MotorDemand& demand() const { return demand_; }

private:
    // Hands the orders standing now down (DemandListener::demand_changed).
    void hand_down();

    const DaemonConfig& config_;
    const SafetyMachine& safety_;
    CommandGate& gate_;
    SafetyActuator& actuator_;
    VehicleEvents& events_;
    MotorDemand demand_;
    bool surfacing_ = false;
};

} // namespace caracara
