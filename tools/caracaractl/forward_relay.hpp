// The topside end of `caracaractl bridge` (issue 46): ssh forwards the vehicle's bridge socket
// to a Unix socket in a private directory (0700, the pilot's alone), and this serves
// 127.0.0.1:PORT, relaying a connection's bytes to that socket only once its request head has
// brought the session's key (ForwardKey). Without it the connection is answered 403 (or the
// redirect that sets the key's cookie) and nothing reaches the vehicle. One thread, poll():
// each connection has 5 s and 16 KiB for its head, at most 64 wait for theirs at once (a new
// one closes the oldest), so another local user's connections cannot lock the pilot out.
#pragma once

#include "tools/caracaractl/forward_key.hpp"

#include <chrono>
#include <cstdint>
#include <list>
#include <string>

namespace caracara::ctl {

class ForwardRelay {
public:
    // Binds 127.0.0.1:port at once (a Failure when it is in use); relays to `upstream`, a Unix socket.
    ForwardRelay(uint16_t port, std::string upstream, ForwardKey key);
    ~ForwardRelay();
    ForwardRelay(const ForwardRelay&) = delete;
    ForwardRelay& operator=(const ForwardRelay&) = delete;

    // Waits up to timeout_ms for something to do and does it; accepts only once `accepting`.
    void run_once(int timeout_ms, bool accepting);

private:
    using Clock = std::chrono::steady_clock;
    enum class Phase { Head, Relay, Answer };
    struct Conn {
        int client = -1, upstream = -1;
        Phase phase = Phase::Head;
        std::string to_upstream, to_client; // bytes read, not yet written on
        bool client_eof = false, upstream_eof = false, client_shut = false, upstream_shut = false;
        Clock::time_point deadline;
    };

    void accept_all();
    void on_head(Conn& c);
    void refuse(Conn& c, const std::string& answer);
    // False when the connection is done (closed).
    bool step(Conn& c, short client_events, short upstream_events);
    static void close_conn(Conn& c);
    // Past a second since the window began: says how many refusals went unlogged, starts another.
    void new_log_window(Clock::time_point now);

    int listen_fd_ = -1;
    uint16_t port_;
    std::string upstream_;
    ForwardKey key_;
    std::list<Conn> conns_;
    Clock::time_point log_window_{}; // refusals logged in the second from here
    int logged_ = 0, unlogged_ = 0;
};

} // namespace caracara::ctl
