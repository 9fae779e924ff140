// The motor commands (SetThrust, SetMotion, SetProfile, and the failsafes' exclusion and
// ascent): accepted or refused by the CommandAcceptance (state, length, range, budget), then
// scaled by the profile and held to the budget (MotorDemand) as the command standing now, and
// handed down to the thrusters through the SafetyActuator. Owned by Vehicle.
#pragma once

#include "core/config.hpp"
#include "core/mixing.hpp"
#include "core/motor_demand.hpp"
#include "core/safety.hpp"
#include "core/status.hpp"
#include "daemon/safety/safety_actuator.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "daemon/vehicle/command_acceptance.hpp"

#include <array>
#include <cstdint>
#include <span>
#include <string_view>

namespace caracara {

class MotorCommands final {
public:
    // `acceptance`: where each command is accepted or refused.
    MotorCommands(const DaemonConfig& config, const SafetyMachine& safety, CommandAcceptance& acceptance,
                  SafetyActuator& actuator, VehicleEvents& events);

    Result set_thrust(std::span<const int32_t> values, std::string_view client);
    Result set_motion(const AxisDemand& demand, std::string_view client);
    // Selects a thrust profile by name; the current command goes out again under it at once.
    Result set_profile(std::string_view name);
    // Eight motor values already in their shape (a packet's, a motor test's, a pulse), with the
    // caller's verdict on its own arguments (CommandAcceptance::motors).
    Result drive(const MotorValues& values, std::string_view client, const Result& range = {});
    // These thrusters to zero and out of the budget's count; the standing command goes on.
    void exclude(const std::array<bool, kMotorCount>& excluded);
    // The ascent (CommandAcceptance::ascent: every other motion command gets Surfacing until a
    // kill ends it).
    Result surface(const AxisDemand& ascent);
    void clear() { demand_.clear(); }

    // What thruster i is to be ordered now: its applied value while the vehicle may drive.
    int32_t order_value(size_t i) const { return safety_.may_drive() ? demand_.applied()[i] : 0; }
    const MotorDemand& demand() const { return demand_; }

private:
    // An accepted command becomes the one standing now, and goes down.
    Result take(const MotorVerdict& v);
    // Hands the orders standing now down (DemandListener::demand_changed).
    void hand_down();

    const DaemonConfig& config_;
    const SafetyMachine& safety_;
    CommandAcceptance& acceptance_;
    SafetyActuator& actuator_;
    VehicleEvents& events_;
    MotorDemand demand_;
};

} // namespace caracara
