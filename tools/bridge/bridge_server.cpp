#include "tools/bridge/bridge_server.hpp"

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <chrono>
#include <cstdio>
#include <sys/stat.h>
#include <unistd.h>

namespace caracara::bridge {

namespace asio = boost::asio;
using Generic = asio::generic::stream_protocol;

namespace {

Generic::endpoint endpoint_of(const ListenConfig& l) {
    if (!l.unix_path.empty())
        return Generic::endpoint(asio::local::stream_protocol::endpoint(l.unix_path));
    return Generic::endpoint(asio::ip::tcp::endpoint(asio::ip::make_address(l.tcp_host), l.tcp_port));
}

} // namespace

BridgeServer::BridgeServer(asio::io_context& io, const ListenConfig& listen, SessionConfig session)
    : io_(io), listen_(listen), session_(std::move(session)),
      telemetry_(io, session_.bus, [this](std::size_t c, uint64_t t, const Payload& p) { publish(c, t, p); }),
      slots_(listen_.max_clients), dives_(io, session_.dives_dir), acceptor_(io), accept_retry_(io) {
    const Generic::endpoint ep = endpoint_of(listen_);
    acceptor_.open(ep.protocol());
    if (!listen_.unix_path.empty()) {
        ::unlink(listen_.unix_path.c_str()); // a socket left by an earlier run
        // Created 0660 (owner and group: the caracara group's pilots), never briefly wider.
        const mode_t old = ::umask(0117);
        boost::system::error_code ec;
        acceptor_.bind(ep, ec);
        ::umask(old);
        if (ec)
            throw boost::system::system_error(ec, "bind " + listen_.unix_path);
    } else {
        acceptor_.set_option(asio::socket_base::reuse_address(true));
        acceptor_.bind(ep);
    }
    acceptor_.listen();
}

void BridgeServer::start() {
    telemetry_.start();
    accept();
}

std::size_t BridgeServer::clients() const { return slots_.taken(); }

void BridgeServer::make_room_for_a_request() {
    sessions_.remove_if([](const std::weak_ptr<Session>& s) { return s.expired(); });
    std::size_t waiting = 0;
    std::shared_ptr<Session> oldest;
    for (const auto& weak : sessions_)
        if (auto s = weak.lock(); s && s->waiting_for_request()) {
            oldest = oldest ? oldest : s;
            ++waiting;
        }
    if (waiting < kMaxWaitingForRequest)
        return;
    // The oldest has had the longest to say something: it goes, never a client with a slot.
    std::fprintf(stderr, "caracara-bridge: %zu connections without a request: closing the oldest\n", waiting);
    oldest->drop();
}

void BridgeServer::accept() {
    acceptor_.async_accept([this](boost::system::error_code ec, Generic::socket socket) {
        if (ec == asio::error::operation_aborted)
            return;
        if (ec) {
            // EMFILE and the like: try again shortly rather than spin.
            std::fprintf(stderr, "caracara-bridge: accept: %s\n", ec.message().c_str());
            accept_retry_.expires_after(std::chrono::milliseconds(200));
            accept_retry_.async_wait([this](boost::system::error_code e) {
                if (!e)
                    accept();
            });
            return;
        }
        make_room_for_a_request();
        auto s = std::make_shared<Session>(io_, std::move(socket), session_, telemetry_, slots_, dives_, seat_);
        sessions_.push_back(s);
        s->start();
        accept();
    });
}

void BridgeServer::publish(std::size_t channel, uint64_t time_ns, const Payload& json) {
    for (auto it = sessions_.begin(); it != sessions_.end();) {
        if (auto s = it->lock()) {
            s->deliver(channel, time_ns, json);
            ++it;
        } else {
            it = sessions_.erase(it);
        }
    }
}

} // namespace caracara::bridge
