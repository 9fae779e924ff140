// Who pilots the vehicle, as clients come and go: a command's client taken as the commanding
// client (SetThrust, SetMotion, a packet, a wheel or a turn), and a client that leaves the bus:
// its zeros when it was commanding, and, when it was the last pilot, the pilot-lost failsafe's
// condition pushed to the failsafes at once (and its end, when a pilot commands again). The roster itself is the safety machine's
// (core/pilot_roster); what the safety machine decides is carried out by the Vehicle (`handle`).
// Owned by the Vehicle.
#pragma once

#include "core/failsafe.hpp"
#include "core/safety.hpp"
#include "core/status.hpp"
#include "daemon/interfaces/failsafe_gate.hpp"
#include "daemon/loop/deadline_timer.hpp"
#include "daemon/vehicle/motor_commands.hpp"
#include "daemon/vehicle/vehicle_condition.hpp"
#include "daemon/interfaces/vehicle_events.hpp"

#include <functional>
#include <string_view>

namespace caracara {

class PilotWatch final {
public:
    using Handle = std::function<void(const SafetyAction&)>;
    PilotWatch(const FailsafeSettings& failsafe, SafetyMachine& safety, const MotorCommands& motors,
               const VehicleCondition& condition, DeadlineTimer& deadline, VehicleEvents& events,
               FailsafeGate& failsafes, Handle handle)
        : failsafe_(failsafe), safety_(safety), motors_(motors), condition_(condition), deadline_(deadline),
          events_(events), failsafes_(failsafes), handle_(std::move(handle)) {}

    // The one place a command is accepted (CommandGate::accept_command: SetThrust, SetMotion, a
    // packet's motors, the wheels, a turn, the failsafe's ascent): refused while a failsafe
    // surfaces (but for the ascent itself) or the state refuses it; else `client` commands,
    // the command timeout restarts, and a new controller is announced.
    Result accept_command(std::string_view client);
    void client_left(std::string_view unique_name);
    // Pushes pilot-lost to the failsafes when it began or ended (a pilot left or commands again;
    // a kill, a clear or a power-off forgets the pilots): after each of the Vehicle's actions.
    void tell_failsafes();

private:
    const FailsafeSettings& failsafe_;
    SafetyMachine& safety_;
    const MotorCommands& motors_;
    const VehicleCondition& condition_;
    DeadlineTimer& deadline_;
    VehicleEvents& events_;
    FailsafeGate& failsafes_;
    Handle handle_;
    bool told_lost_ = false; // pilot-lost as last pushed
};

} // namespace caracara
