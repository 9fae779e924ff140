// How Vehicle hands its motor values down to what carries them to the thrusters (the control
// loop) without knowing it: each new set of orders, and the zeros of a kill, a timeout or a
// client that left. The value travels with the call; nothing is pulled back up.
#pragma once

#include "core/motor.hpp"
#include "core/zero_order.hpp"

namespace caracara {

class DemandListener {
public:
    virtual ~DemandListener() = default;
    // What each thruster is to be ordered now (its applied value while the vehicle may drive):
    // the orders that changed, or are not on the wire, go out at once.
    virtual void demand_changed(const MotorValues& orders) = 0;
    // Zero to every thruster, back to back (see ZeroOrder).
    virtual void zero_all(ZeroOrder where) = 0;
};

} // namespace caracara
