// The failsafes as the objects below them see them (daemon/failsafe/failsafe_monitor implements
// it): every source of a fixed condition (core/failsafe.hpp, kFailsafeTable) pushes it here,
// and the Vehicle asks whether a kill may be cleared.
#pragma once

#include "core/failsafe.hpp"
#include "core/status.hpp"

#include <string_view>

namespace caracara {

class FailsafeGate {
public:
    virtual ~FailsafeGate() = default;
    // Ok, or FailsafeActive while a failsafe that kills (or surfaces) still holds.
    virtual Result clear_kill_refusal() const = 0;
    // Condition `c` holds now, or has cleared; `reason` says what happened (the kill's reason
    // where the row's kill source is not "failsafe"). Decided at once, not at the next reading:
    // a kill is immediate and a persistence time counts from the event.
    virtual void push(FailsafeCondition c, bool holds, std::string_view reason) = 0;
};

} // namespace caracara
