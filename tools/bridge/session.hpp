// One Foxglove client: the HTTP upgrade (subprotocol foxglove.websocket.v1, and the token when
// the bridge listens on TCP), serverInfo and advertise, then its frames through ClientProtocol
// and its commands through its own CommandLink. Messages to it wait in a bounded queue: when
// the client does not keep up, the oldest messages are dropped, so it never holds up the
// bridge or another client. When it goes (closed, dropped, refused), its D-Bus connection
// closes with it, and caracarad zeroes the thrust it commanded.
#pragma once

#include "tools/bridge/client_protocol.hpp"
#include "tools/bridge/command_link.hpp"
#include "tools/bridge/send_queue.hpp"
#include "tools/bridge/telemetry.hpp"

#include <boost/asio/generic/stream_protocol.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>
#include <boost/beast/websocket/stream.hpp>
#include <memory>
#include <string>

namespace caracara::bridge {

struct SessionConfig {
    caracara::dbus::BusChoice bus;
    std::string token;                  // required in the request when not empty (TCP)
    std::size_t max_message_bytes = 64 * 1024;
    std::size_t max_queued = 256;       // messageData frames waiting for a slow client
    std::string cockpit_dir;            // the cockpit's files, served to plain HTTP GETs (docs/cockpit.md)
    std::string dives_dir;              // the recorded dives, under /dives/ (with the token, on TCP)
};

class Session : public std::enable_shared_from_this<Session> {
public:
    using Socket = boost::asio::generic::stream_protocol::socket;

    Session(boost::asio::io_context& io, Socket socket, const SessionConfig& config, Telemetry& telemetry);
    void start();
    // A channel's new message, sent to each of this client's subscriptions of it.
    void deliver(std::size_t channel, uint64_t time_ns, const Payload& json);
    uint64_t dropped() const { return queue_.dropped(); }

private:
    using Frame = SendQueue::Frame;

    void on_request(boost::system::error_code ec);
    void reject(boost::beast::http::status status, std::string body);
    void answer(std::shared_ptr<boost::beast::http::response<boost::beast::http::string_body>> res);
    void on_accept(boost::system::error_code ec);
    void read();
    void on_frame(boost::system::error_code ec);
    void handle(const Outcome& outcome);
    void send_text(std::string text);
    void queue(Frame f);
    void write_next();
    void end(const char* why);

    boost::asio::io_context& io_;
    boost::beast::websocket::stream<Socket> ws_;
    boost::asio::steady_timer handshake_timer_; // a connection that never upgrades is closed
    const SessionConfig& config_;
    Telemetry& telemetry_;
    boost::beast::flat_buffer buffer_;
    boost::beast::http::request<boost::beast::http::string_body> request_;
    ClientProtocol protocol_;
    std::unique_ptr<CommandLink> link_;
    SendQueue queue_;
    bool open_ = false, ended_ = false;
};

} // namespace caracara::bridge
