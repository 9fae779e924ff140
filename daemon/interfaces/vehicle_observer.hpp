// What the daemon's objects tell those who show or keep the vehicle's state (D-Bus, the dive
// recorder, systemd's status line): which vehicle properties changed, periodic telemetry, and
// the I2C bus going and coming back.
#pragma once

#include "core/failsafe_policy.hpp"

#include <cstdint>
#include <string>

namespace caracara {

// Which vehicle properties changed, for PropertiesChanged.
enum VehicleChange : uint32_t {
    kChangeState = 1u << 0,      // State, KillSource, SurfacingUntil
    kChangeMotors = 1u << 1,     // MotorValues, RequestedValues, BudgetLimit, Saturated
    kChangeLeds = 1u << 2,
    kChangeController = 1u << 3, // Controller
    kChangeBus = 1u << 4,        // the Bus object's State and recovery figures
    kChangeProfile = 1u << 5,    // Profile, ProfileFactor
    kChangeFaults = 1u << 6,     // a thruster's fault bits (its Faults property goes with telemetry)
    kChangeFailsafes = 1u << 7,  // Failsafes (the active ones), PilotLostKillAt
};

class VehicleObserver {
public:
    virtual ~VehicleObserver() = default;
    virtual void vehicle_changed(uint32_t changes) = 0;
    // The rest only some observers care about.
    // Periodic: thruster, Teensy and bus telemetry, command age, cycles.
    virtual void telemetry() {}
    // The I2C bus was found locked up / came back after a recovery.
    virtual void bus_lost(const std::string& /*reason*/) {}
    virtual void bus_restored(uint32_t /*pulses*/, double /*milliseconds*/) {}
    // Every control-loop cycle (the dive recorder's samples).
    virtual void cycle(uint64_t /*now_ns*/) {}
    // A command's orders were handed to the bus worker (true) and are now all on the wire
    // (false): what announces the command may wait for the wire it describes.
    virtual void orders_in_flight(bool /*in_flight*/) {}
    // A failsafe was raised or its condition cleared (daemon/failsafe_monitor).
    virtual void failsafe(const ActiveFailsafe& /*f*/, bool /*raised*/) {}
    // A motor test's order was accepted (daemon/commissioning/motor_test): told at once, so the
    // dive has a test shorter than a loop cycle too. Its end shows in MotorTest itself.
    virtual void motor_test(int32_t /*thruster*/, int32_t /*value*/) {}
};

} // namespace caracara
