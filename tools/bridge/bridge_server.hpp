// The listening side of caracara-bridge: a Unix socket (the default, reached over SSH with
// ssh -L) or, when configured, a TCP address (then every client must bring the token). Each
// connection becomes a Session; the Telemetry's messages go to every session. A connection
// takes a client slot only once its request and token are good (ClientSlots); before that it
// has a few seconds (Session), and at most kMaxWaitingForRequest wait at once (a new one
// closes the oldest), so stalled or tokenless connections never lock out a pilot. One pilot's
// seat (PilotSeat) for all of them.
#pragma once

#include "tools/bridge/client_slots.hpp"
#include "tools/bridge/dive_worker.hpp"
#include "tools/bridge/pilot_seat.hpp"
#include "tools/bridge/session.hpp"
#include "tools/bridge/telemetry.hpp"

#include <boost/asio/basic_socket_acceptor.hpp>
#include <boost/asio/generic/stream_protocol.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <list>
#include <memory>
#include <string>

namespace caracara::bridge {

struct ListenConfig {
    std::string unix_path;        // the Unix socket (mode 0660), when not empty
    std::string tcp_host;         // or a TCP address and port
    uint16_t tcp_port = 0;
    std::size_t max_clients = 16; // WebSocket clients (with their token) at once
};

class BridgeServer {
public:
    static constexpr std::size_t kMaxWaitingForRequest = 64;

    // Binds at once (throws std::system_error when it cannot).
    BridgeServer(boost::asio::io_context& io, const ListenConfig& listen, SessionConfig session);
    void start();
    std::size_t clients() const;

private:
    void accept();
    void make_room_for_a_request();
    void publish(std::size_t channel, uint64_t time_ns, const Payload& json);

    boost::asio::io_context& io_;
    ListenConfig listen_;
    SessionConfig session_;
    Telemetry telemetry_;
    ClientSlots slots_;
    DiveWorker dives_;
    PilotSeat seat_; // one pilot's seat for every client of this bridge: the vehicle's
    boost::asio::basic_socket_acceptor<boost::asio::generic::stream_protocol> acceptor_;
    boost::asio::steady_timer accept_retry_; // after a failed accept (no descriptor left)
    std::list<std::weak_ptr<Session>> sessions_;
};

} // namespace caracara::bridge
