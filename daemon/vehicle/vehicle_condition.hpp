// The vehicle's condition as callers see it, read from the safety machine, the bus, the
// safety lines and the failsafes: why a command is refused (state_error), why a ClearKill or a
// PowerOff is refused, the state's name (fault when no thruster can be reached). Owned by Vehicle.
#pragma once

#include "core/safety.hpp"
#include "core/status.hpp"
#include "daemon/bus/thruster_bus.hpp"
#include "daemon/interfaces/failsafe_gate.hpp"
#include "daemon/safety/safety_lines.hpp"

#include <cstdint>
#include <string_view>

namespace caracara {

class VehicleCondition final {
public:
    VehicleCondition(const SafetyMachine& safety, const ThrusterBus& bus, const SafetyLines& lines,
                     const FailsafeGate& failsafes)
        : safety_(safety), bus_(bus), lines_(lines), failsafes_(failsafes) {}

    // Ok when the vehicle is ready to move; else the error a caller gets (Killed, Arming, ...).
    Result state_error() const;
    // Ok when nothing keeps a kill from being cleared (the bus, a thruster, the kill output,
    // a failsafe); the safety machine has the last word.
    Result clear_kill_refusal() const;
    // Ok when `confirmation` is the one PowerOff asks for: power-off is irreversible.
    static constexpr const char* kPowerOffConfirmation = "power-off";
    static Result power_off_refusal(std::string_view confirmation);
    std::string_view state_name() const;
    std::string_view kill_source_name() const;
    int64_t command_age_ms() const;

private:
    const SafetyMachine& safety_;
    const ThrusterBus& bus_;
    const SafetyLines& lines_;
    const FailsafeGate& failsafes_;
};

} // namespace caracara
