// Who pilots the vehicle, as clients come and go (a command's client is taken as the commanding
// client by the CommandAcceptance, which tells this watch): a client that leaves the bus:
// its zeros when it was commanding, and, when it was the last pilot, the pilot-lost failsafe's
// condition pushed to the failsafes at once (and its end, when a pilot commands again). The roster itself is the safety machine's
// (core/pilot_roster); what the safety machine decides is carried out by the Vehicle (`handle`).
// Owned by the Vehicle.
#pragma once

#include "core/failsafe.hpp"
#include "core/safety.hpp"
#include "daemon/interfaces/failsafe_gate.hpp"

#include <functional>
#include <string_view>

namespace caracara {

class PilotWatch final {
public:
    using Handle = std::function<void(const SafetyAction&)>;
    PilotWatch(const FailsafeSettings& failsafe, SafetyMachine& safety, FailsafeGate& failsafes, Handle handle)
        : failsafe_(failsafe), safety_(safety), failsafes_(failsafes), handle_(std::move(handle)) {}

    void client_left(std::string_view unique_name);
    // Pushes pilot-lost to the failsafes when it began or ended (a pilot left or commands again;
    // a kill, a clear or a power-off forgets the pilots): after each of the Vehicle's actions and
    // each accepted command.
    void tell_failsafes();

private:
    const FailsafeSettings& failsafe_;
    SafetyMachine& safety_;
    FailsafeGate& failsafes_;
    Handle handle_;
    bool told_lost_ = false; // pilot-lost as last pushed
};

} // namespace caracara
