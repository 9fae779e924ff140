// A motor test (docs/commissioning.md): one thruster run at a bounded value, the others held
// at zero, for as long as the caller keeps asking. It is an ordinary motor command from the
// caller's client (MotorCommands::drive: the same budget, state checks, commanding client and path
// to the wire as SetThrust), so whatever ends a command ends it at once: a kill zeroes it, the
// caller leaving the bus zeroes it (PilotWatch), a pilot's command or a second test replaces
// it. What it adds: the value's bound (commissioning.motor_test_limit), armed only, and the
// keep-alive: without a repeat within commissioning.motor_test_keepalive_ms the thruster stops.
#pragma once

#include "core/config.hpp"
#include "core/motor.hpp"
#include "core/status.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "daemon/loop/deadline_timer.hpp"
#include "daemon/vehicle/vehicle.hpp"
#include "drivers/platform/event_loop.hpp"

#include <cstdint>
#include <string>
#include <string_view>

namespace caracara {

class MotorTest final {
public:
    MotorTest(const DaemonConfig& config, Vehicle& vehicle, VehicleEvents& events);
    // Makes the keep-alive timer. "" or why it could not.
    std::string start(sd_event* event);
    void stop() { keepalive_.stop(); }

    // Thruster `thruster` (0..7) at `value`, every other at zero, until the next call from the
    // same caller or the keep-alive runs out. Refused (and nothing changes) for a thruster out
    // of range, a value beyond the limit, or a vehicle that may not drive.
    Result run(int32_t thruster, int32_t value, std::string_view client);
    // The thruster under test now, or -1: the test's command is still the one standing (not
    // replaced by a pilot, a kill or the caller leaving) and the vehicle may drive.
    int32_t active_thruster() const;
    int32_t value() const { return active_thruster() < 0 ? 0 : value_; }
    int32_t limit() const { return config_.commissioning.motor_test_limit; }

private:
    void expired();
    MotorValues values() const;

    const DaemonConfig& config_;
    Vehicle& vehicle_;
    VehicleEvents& events_; // each accepted order, for the dive
    DeadlineTimer keepalive_;
    bool running_ = false;
    int32_t thruster_ = -1;
    int32_t value_ = 0;
    std::string client_;
};

} // namespace caracara
