// Whether the vehicle's state allows a command: asked by the objects that move something
// (the Teensy's wheels and turns) without their knowing the safety machine.
#pragma once

#include "core/status.hpp"

namespace caracara {

class CommandGate {
public:
    virtual ~CommandGate() = default;
    // Ok when the vehicle is ready to move; else the error a caller gets (Killed, Arming, ...).
    virtual Result state_error() const = 0;
    virtual bool powered_off() const = 0;
};

} // namespace caracara
