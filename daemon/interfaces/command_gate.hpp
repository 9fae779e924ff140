// Whether the vehicle's state allows a command, and taking one: asked by the objects that move
// something (the Teensy's wheels and turns) without their knowing the safety machine. The
// vehicle's CommandAcceptance answers (daemon/vehicle/command_acceptance.hpp).
#pragma once

#include "core/status.hpp"

#include <string_view>

namespace caracara {

class CommandGate {
public:
    virtual ~CommandGate() = default;
    // Ok when the vehicle is ready to move; else the error a caller gets (Killed, Arming, ...).
    virtual Result state_error() const = 0;
    virtual bool powered_off() const = 0;
    // A command that moves something, from `client`, with the caller's own verdict on its
    // arguments (`range`, {} when they are good): refused with the state's error first, then
    // with `range`; else accepted: it restarts the command timeout and makes `client` the
    // commanding client, as SetThrust does.
    virtual Result accept_command(std::string_view client, const Result& range) = 0;
};

} // namespace caracara
