// One Foxglove client: the HTTP upgrade (its Origin, OriginCheck; subprotocol
// foxglove.websocket.v1, and the token when the bridge listens on TCP), serverInfo and advertise, then its frames through ClientProtocol
// and its commands through its own CommandLink. Messages to it wait in a bounded queue: when
// the client does not keep up, the oldest messages are dropped, so it never holds up the
// bridge or another client. Its replies and status messages are bounded in bytes: past
// read_pause_bytes it is not read until it has read them, past max_reply_bytes it is closed
// with the reason. It takes one of the client slots only once its request and token are
// good; /dives/ requests are answered by the DiveWorker. When it goes (closed, dropped,
// refused), its D-Bus connection closes with it, and caracarad zeroes the thrust it commanded.
#pragma once

#include "tools/bridge/client_protocol.hpp"
#include "tools/bridge/client_slots.hpp"
#include "tools/bridge/command_link.hpp"
#include "tools/bridge/origin_check.hpp"
#include "tools/bridge/send_queue.hpp"
#include "tools/bridge/telemetry.hpp"

#include <boost/asio/generic/stream_protocol.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>
#include <boost/beast/websocket/stream.hpp>
#include <chrono>
#include <memory>
#include <string>

namespace caracara::bridge {

class DiveWorker;

struct SessionConfig {
    caracara::dbus::BusChoice bus;
    std::string token;                  // required in the request when not empty (TCP)
    OriginCheck origins;                // which pages may upgrade or read /dives/ (--allow-origin)
    std::size_t max_message_bytes = 64 * 1024;
    std::size_t max_queued = 256;       // messageData frames waiting for a slow client
    std::size_t max_reply_bytes = 256 * 1024; // replies and status messages waiting: past it, closed
    std::size_t read_pause_bytes = 64 * 1024; // replies waiting past which the client is not read
    std::string cockpit_dir;            // the cockpit's files, served to plain HTTP GETs (docs/cockpit.md)
    std::string dives_dir;              // the recorded dives, under /dives/ (with the token, on TCP)
};

class Session : public std::enable_shared_from_this<Session> {
public:
    using Socket = boost::asio::generic::stream_protocol::socket;

    Session(boost::asio::io_context& io, Socket socket, const SessionConfig& config, Telemetry& telemetry,
            ClientSlots& slots, DiveWorker& dives);
    void start();
    // Still waiting for its HTTP request (BridgeServer bounds these apart from the client slots).
    bool waiting_for_request() const { return !got_request_; }
    // Closes the connection now (one waiting for its request, to make room).
    void drop();
    // A channel's new message, sent to each of this client's subscriptions of it.
    void deliver(std::size_t channel, uint64_t time_ns, const Payload& json);
    uint64_t dropped() const { return queue_.dropped(); }

private:
    using Frame = SendQueue::Frame;

    void on_request(boost::system::error_code ec);
    void reject(boost::beast::http::status status, std::string body);
    // False (the request answered 403 and logged) when a browser page of another origin sent it.
    bool origin_taken(bool upgrade);
    // ticket: a DiveWorker's, held until the answer is written.
    void answer(std::shared_ptr<boost::beast::http::response<boost::beast::http::string_body>> res,
                std::shared_ptr<void> ticket = nullptr);
    void on_accept(boost::system::error_code ec);
    void read();
    void on_frame(boost::system::error_code ec);
    void handle(const Outcome& outcome);
    void send_text(std::string text);
    void queue(Frame f);
    void write_next();
    // why: logged when not null; tell_client: a close frame with it, when the client is open.
    void end(const char* why, bool tell_client = false);
    void close_after(std::chrono::steady_clock::duration d);
    void close_socket();

    boost::asio::io_context& io_;
    boost::beast::websocket::stream<Socket> ws_;
    boost::asio::steady_timer timer_; // the request, an HTTP answer, a close frame: each in bounded time
    const SessionConfig& config_;
    Telemetry& telemetry_;
    ClientSlots& slots_;
    DiveWorker& dives_;
    std::shared_ptr<void> slot_; // a client slot, held from the upgrade on
    boost::beast::flat_buffer buffer_;
    boost::beast::http::request<boost::beast::http::string_body> request_;
    ClientProtocol protocol_;
    std::unique_ptr<CommandLink> link_;
    SendQueue queue_;
    bool got_request_ = false, open_ = false, ended_ = false;
    bool paused_ = false; // not reading: its replies wait past read_pause_bytes
};

} // namespace caracara::bridge
