// One pilot's own connection to caracarad (client::PilotConnection, driven from the bridge's
// io_context): each WebSocket client gets one, so the daemon's
// per-client rules hold per pilot (its thrust goes to zero when this connection closes; the
// command timeout, which is the vehicle's, zeroes it when commands stop; a motor test stops when
// its keep-alives stop or this connection closes). Commands are sent asynchronously and in order; a refusal comes back with
// the daemon's error name, and a reply that carries something (command_spec's reply) as JSON.
#pragma once

#include "tools/bridge/bus_watch.hpp"
#include "tools/bridge/command.hpp"
#include "tools/client/pilot_connection.hpp"

#include <boost/asio/io_context.hpp>
#include <functional>
#include <memory>
#include <string>

namespace caracara::bridge {

class CommandLink {
public:
    // on_refused(command topic, D-Bus error name, message); on_answered(command topic, the
    // reply as JSON); on_lost: the connection closed.
    using Refused = std::function<void(std::string_view topic, const std::string& name, const std::string& message)>;
    using Answered = std::function<void(std::string_view topic, const std::string& json)>;

    // Connects at once; throws std::runtime_error when the bus cannot be reached.
    CommandLink(boost::asio::io_context& io, const caracara::dbus::BusChoice& bus, Refused on_refused,
                Answered on_answered, std::function<void()> on_lost);
    ~CommandLink();

    // quiet: a refusal is not told (the bridge's own zero at a take-over of the seat, which a
    // killed vehicle refuses with nothing to stop).
    void send(const Command& c, bool quiet = false);
    // The connection's unique bus name (the daemon's Controller when this client commands).
    std::string unique_name() const { return connection_.unique_name(); }

private:
    void replied(const CommandSpec& spec, bool quiet, const client::PilotConnection::Reply& reply);

    client::PilotConnection connection_;
    std::unique_ptr<BusWatch> watch_;
    Refused on_refused_;
    Answered on_answered_;
};

} // namespace caracara::bridge
