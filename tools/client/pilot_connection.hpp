// A pilot's own connection to caracarad, for the programs that speak for remote pilots (the
// bridge's WebSocket clients, caracara-ros's DDS writers): one connection per pilot, so that the
// daemon's per-client rules hold per pilot (its thrust goes to zero when the connection closes).
// Calls to org.caracara.Vehicle1 are sent asynchronously and in order, without auto-start; each
// reply, or the refusal to send, comes back to its callback. The owner drives the connection from
// its loop (sd_bus_attach_event, or the bridge's BusWatch) and owns that, declared after this.
#pragma once

#include "drivers/sdbus/sdbus.hpp"

#include <chrono>
#include <functional>
#include <string>

namespace caracara::client {

class PilotConnection {
public:
    // The outcome of one call: `message` is the reply (read its values from it) or null when the
    // call was not sent; `error_name` is empty on success.
    struct Reply {
        sd_bus_message* message;
        std::string error_name;
        std::string error_message;
        bool ok() const { return error_name.empty(); }
    };
    using OnReply = std::function<void(const Reply&)>;
    // Appends the call's arguments; returns a negative errno when it cannot.
    using Append = std::function<int(sd_bus_message*)>;

    // The error a call that could not be sent is answered with.
    static constexpr const char* kSendFailed = "org.caracara.Client.Error.SendFailed";

    // Connects at once, the connection named `description` on the bus; throws
    // std::runtime_error when the bus cannot be reached.
    PilotConnection(const caracara::dbus::BusChoice& bus, const char* description);
    PilotConnection(const PilotConnection&) = delete;
    PilotConnection& operator=(const PilotConnection&) = delete;

    // Vehicle1.`member`(arguments); `on_reply` runs once, from the owner's loop (or at once,
    // with kSendFailed, when the call cannot be queued). timeout 0: sd-bus's default.
    void call(const char* member, const Append& append, OnReply on_reply,
              std::chrono::microseconds timeout = std::chrono::microseconds(0));

    sd_bus* bus() const { return bus_.get(); }
    // The connection's unique bus name (the daemon's Controller when this pilot commands).
    std::string unique_name() const;

private:
    caracara::dbus::BusPtr bus_;
};

} // namespace caracara::client
