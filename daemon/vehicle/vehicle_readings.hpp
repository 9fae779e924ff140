// The vehicle as read: its state and kill source, who commands and since when, whether it may
// drive, the motor values (requested, applied, the budget) and the thrust profile. The readers
// (the D-Bus objects, the dive files, the failsafes, commissioning, the service status) read
// here; what changes the vehicle is the Vehicle's (kill, clear, power-off) and its
// MotorCommands' (the motor commands). Owned by Vehicle, handed out read-only.
#pragma once

#include "core/motor_demand.hpp"
#include "core/safety.hpp"
#include "daemon/vehicle/command_acceptance.hpp"
#include "daemon/vehicle/motor_commands.hpp"
#include "daemon/vehicle/vehicle_condition.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace caracara {

class VehicleReadings final {
public:
    VehicleReadings(const SafetyMachine& safety, const VehicleCondition& condition, const CommandAcceptance& acceptance,
                    const MotorCommands& motors)
        : safety_(safety), condition_(condition), acceptance_(acceptance), motors_(motors) {}

    const SafetyMachine& safety() const { return safety_; }
    std::string_view state_name() const { return condition_.state_name(); }
    std::string_view kill_source_name() const { return condition_.kill_source_name(); }
    int64_t command_age_ms() const { return condition_.command_age_ms(); }
    const std::string& controller_client() const { return safety_.commands().client(); }
    bool may_drive() const { return safety_.may_drive(); }
    bool kill_output_asserted() const { return safety_.kill_output_asserted(); }
    // A failsafe's ascent runs (CommandAcceptance::ascent).
    bool surfacing() const { return acceptance_.surfacing(); }

    // What thruster i is to be ordered now: its applied value while the vehicle may drive.
    int32_t order_value(size_t i) const { return motors_.order_value(i); }
    const MotorValues& motor_values() const { return motors_.demand().applied(); }
    const MotorValues& requested_values() const { return motors_.demand().requested(); }
    int32_t budget_limit() const { return motors_.demand().limit(); }
    bool saturated() const { return motors_.demand().saturated(); }
    const ThrustProfile& profile() const { return motors_.demand().profile(); }

private:
    const SafetyMachine& safety_;
    const VehicleCondition& condition_;
    const CommandAcceptance& acceptance_;
    const MotorCommands& motors_;
};

} // namespace caracara
