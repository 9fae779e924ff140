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
      acceptor_(io), accept_retry_(io) {
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

std::size_t BridgeServer::clients() {
    sessions_.remove_if([](const std::weak_ptr<Session>& s) { return s.expired(); });
    return sessions_.size();
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
        if (clients() >= listen_.max_clients) {
            std::fprintf(stderr, "caracara-bridge: refusing a client: %zu connected\n", listen_.max_clients);
        } else {
            auto s = std::make_shared<Session>(io_, std::move(socket), session_, telemetry_);
            sessions_.push_back(s);
            s->start();
        }
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
