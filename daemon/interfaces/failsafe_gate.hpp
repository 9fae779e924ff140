// What the Vehicle asks of the failsafes, without knowing them (daemon/failsafe_monitor
// implements it): whether a kill may be cleared, and to look now when a condition of the
// vehicle's own changed.
#pragma once

#include "core/status.hpp"

namespace caracara {

class FailsafeGate {
public:
    virtual ~FailsafeGate() = default;
    // Ok, or FailsafeActive while a failsafe that kills (or surfaces) still holds.
    virtual Result clear_kill_refusal() const = 0;
    // A fixed condition may have changed (the last pilot left, the Teensy link went or came
    // back): decided now, not at the next reading, so that a kill is at once and a
    // persistence time counts from the event.
    virtual void conditions_changed() = 0;
};

} // namespace caracara
