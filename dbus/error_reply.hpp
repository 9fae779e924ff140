// A command's Result as its D-Bus reply: org.caracara.Vehicle1.Error.<status_name()> on failure.
// Malformed arguments never get this far: sd-bus answers them with the standard InvalidArgs.
#pragma once

#include "core/status.hpp"

#include <string>
#include <systemd/sd-bus.h>

namespace caracara::dbus {

std::string error_name(Status s);
// Replies to `call` (now, or later for a deferred reply): an empty return, or the error.
int reply(sd_bus_message* call, const Result& result);

} // namespace caracara::dbus
