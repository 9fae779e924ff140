// What the control loop asks between two bus transactions: is a caller waiting? The D-Bus
// connection answers it (dbus/bus_input_probe.hpp), so daemon/ never touches sd-bus itself.
#pragma once

namespace caracara {

class InputProbe {
public:
    virtual ~InputProbe() = default;
    // A message already read and queued, waiting for dispatch.
    virtual bool queued() const = 0;
    // The fd that becomes readable when a message arrives (polled together with the kill
    // switch's, one poll() for both), or -1.
    virtual int fd() const = 0;
};

} // namespace caracara
