// What the Vehicle asks of the failsafes before it clears a kill, without knowing them
// (daemon/failsafe_monitor implements it).
#pragma once

#include "core/status.hpp"

namespace caracara {

class FailsafeGate {
public:
    virtual ~FailsafeGate() = default;
    // Ok, or FailsafeActive while a failsafe that kills (or surfaces) still holds.
    virtual Result clear_kill_refusal() const = 0;
};

} // namespace caracara
