// What every inspection object shares: the root path, the error name for a refused argument,
// and a reply built in place.
#pragma once

#include "drivers/sdbus/sdbus.hpp"

namespace caracara::sim {

inline constexpr const char* kInspectRoot = "/org/caracara/Simulator1";
inline constexpr const char* kInspectInvalid = "org.caracara.Simulator1.Error.InvalidArgument";

// Replies to `call` with what `fill(reply)` appends (a negative return is the failure).
template <class Fill>
int reply_with(sd_bus_message* call, Fill fill) {
    sd_bus_message* reply = nullptr;
    int r = sd_bus_message_new_method_return(call, &reply);
    if (r < 0)
        return r;
    dbus::MessagePtr guard(reply);
    if ((r = fill(reply)) < 0)
        return r;
    return sd_bus_send(nullptr, reply, nullptr);
}

} // namespace caracara::sim
