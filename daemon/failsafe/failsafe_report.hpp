// How the failsafes are told: one journal line per transition, and each to VehicleEvents
// (D-Bus, the dive recorder, STATUS=). Owned by the FailsafeMonitor.
#pragma once

#include "core/failsafe.hpp"
#include "core/failsafe_policy.hpp"
#include "daemon/interfaces/vehicle_events.hpp"

#include <string>

namespace caracara {

class FailsafeReport final {
public:
    FailsafeReport(const FailsafeSettings& settings, VehicleEvents& events) : settings_(settings), events_(events) {}
    // "water-detect surface thruster 3": a failsafe in the journal, a refusal and a kill's reason.
    static std::string describe(const ActiveFailsafe& f);
    void tell(const FailsafeTransitions& ts) const;

private:
    const FailsafeSettings& settings_;
    VehicleEvents& events_;
};

} // namespace caracara
