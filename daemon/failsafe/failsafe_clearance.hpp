// Whether the failsafes let a kill be cleared (a failsafe that kills or surfaces, and holds,
// refuses ClearKill by its name), and ClearKillOverride: a ClearKill with one condition's
// failsafes set aside, which then only warn until it clears. Owned by the FailsafeMonitor.
#pragma once

#include "core/failsafe_policy.hpp"
#include "core/status.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "daemon/vehicle/vehicle.hpp"

#include <optional>
#include <string_view>

namespace caracara {

class FailsafeClearance final {
public:
    FailsafeClearance(FailsafePolicy& policy, Vehicle& vehicle, VehicleEvents& events)
        : policy_(policy), vehicle_(vehicle), events_(events) {}
    // Ok, or FailsafeActive while a failsafe that kills (or surfaces) still holds.
    Result refusal() const;
    // ClearKill for a pilot who means it: the named condition's failsafes warn until it clears.
    Result clear_kill_override(std::string_view condition, std::string_view caller);

private:
    FailsafePolicy& policy_;
    Vehicle& vehicle_;
    VehicleEvents& events_;
    std::optional<FailsafeCondition> overriding_; // set aside during ClearKillOverride's ClearKill
};

} // namespace caracara
