// A command's Result as its D-Bus reply: org.caracara.Vehicle1.Error.<status_name()> on failure.
// Malformed arguments never get this far: sd-bus answers them with the standard InvalidArgs.
#pragma once

#include "core/status.hpp"
#include "daemon/loop/completion.hpp"
#include "drivers/sdbus/sdbus.hpp"

#include <functional>
#include <string>
#include <systemd/sd-bus.h>

namespace caracara::dbus {

// The caller's unique bus name: who commands the vehicle, for the command timeout and client loss.
inline std::string sender(sd_bus_message* m) {
    const char* s = sd_bus_message_get_sender(m);
    return s ? s : "";
}

std::string error_name(Status s);
// Replies to `call` (now, or later for a deferred reply): an empty return, or the error.
int reply(sd_bus_message* call, const Result& result);
// The reply to `call` as a Completion, for the daemon to hand the result back later; the
// handler then returns 1 (the reply is on its way).
Completion reply_later(sd_bus_message* call);
// The reply to `call` as a Completion whose success carries values: `fill` appends them to the
// method return (0 or -errno); a failure, or a reply that cannot be built, is the error.
Completion reply_filled_later(sd_bus_message* call, std::function<int(sd_bus_message* out)> fill);

} // namespace caracara::dbus
