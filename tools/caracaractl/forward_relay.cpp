#include "tools/caracaractl/forward_relay.hpp"

#include "tools/client/client.hpp"

#include <algorithm>
#include <arpa/inet.h>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>
#include <vector>

namespace caracara::ctl {

using client::Failure;

namespace {

constexpr std::size_t kMaxHead = 16 * 1024;        // a request head past this is refused (431)
constexpr std::size_t kMaxBuffered = 256 * 1024;   // read no further one way while this waits
constexpr std::size_t kMaxWaitingForHead = 64;     // past this, a new connection closes the oldest
constexpr std::size_t kMaxConnections = 256;       // past this, a new connection is closed at once (2 fds each)
constexpr int kRefusalsLoggedPerSecond = 10;       // the rest counted, so a flood cannot bury the terminal
constexpr auto kHeadTimeout = std::chrono::seconds(5);
constexpr auto kAnswerTimeout = std::chrono::seconds(5);  // to read a refusal, or to close after the vehicle's end

// Reads what there is onto `to`; false at the end of the stream or on an error.
bool read_into(int fd, std::string& to, std::size_t max) {
    char buf[64 * 1024];
    while (to.size() < max) {
        const ssize_t n = ::recv(fd, buf, std::min(sizeof buf, max - to.size()), 0);
        if (n > 0) {
            to.append(buf, static_cast<std::size_t>(n));
            continue;
        }
        if (n < 0 && (errno == EAGAIN || errno == EINTR))
            return true;
        return false;
    }
    return true;
}

// Writes what it can of `from`; false on an error (the peer gone).
bool write_from(int fd, std::string& from) {
    while (!from.empty()) {
        const ssize_t n = ::send(fd, from.data(), from.size(), MSG_NOSIGNAL);
        if (n > 0) {
            from.erase(0, static_cast<std::size_t>(n));
            continue;
        }
        return n < 0 && (errno == EAGAIN || errno == EINTR);
    }
    return true;
}

std::string status_answer(const char* status, const std::string& body) {
    return std::string("HTTP/1.1 ") + status + "\r\nServer: caracaractl\r\nContent-Type: text/plain; charset=utf-8\r\n" +
           "Content-Length: " + std::to_string(body.size()) + "\r\nConnection: close\r\n\r\n" + body;
}

} // namespace

ForwardRelay::ForwardRelay(uint16_t port, std::string upstream, ForwardKey key)
    : port_(port), upstream_(std::move(upstream)), key_(std::move(key)) {
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (listen_fd_ < 0)
        throw Failure{client::kExitUnavailable, std::string("socket: ") + std::strerror(errno)};
    const int one = 1;
    ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one); // not past a listener: only TIME_WAIT
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 || ::listen(listen_fd_, 128) != 0) {
        const int e = errno;
        ::close(listen_fd_);
        listen_fd_ = -1;
        if (e == EADDRINUSE)
            throw Failure{client::kExitRefused, "localhost:" + std::to_string(port) + " is in use; choose another with --port"};
        throw Failure{client::kExitUnavailable, "127.0.0.1:" + std::to_string(port) + ": " + std::strerror(e)};
    }
}

ForwardRelay::~ForwardRelay() {
    for (Conn& c : conns_)
        close_conn(c);
    if (listen_fd_ >= 0)
        ::close(listen_fd_);
}

void ForwardRelay::close_conn(Conn& c) {
    if (c.client >= 0)
        ::close(c.client);
    if (c.upstream >= 0)
        ::close(c.upstream);
    c.client = c.upstream = -1;
}

void ForwardRelay::accept_all() {
    for (;;) {
        const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
        if (fd < 0)
            return; // EAGAIN, or out of descriptors: the next turn tries again
        if (conns_.size() >= kMaxConnections) {
            ::close(fd);
            continue;
        }
        const auto waiting = std::count_if(conns_.begin(), conns_.end(), [](const Conn& c) { return c.phase == Phase::Head; });
        if (static_cast<std::size_t>(waiting) >= kMaxWaitingForHead) {
            // The oldest has had the longest to say something; never a relayed one.
            const auto oldest = std::find_if(conns_.begin(), conns_.end(), [](const Conn& c) { return c.phase == Phase::Head; });
            close_conn(*oldest);
            conns_.erase(oldest);
        }
        Conn c;
        c.client = fd;
        c.deadline = Clock::now() + kHeadTimeout;
        conns_.push_back(std::move(c));
    }
}

void ForwardRelay::refuse(Conn& c, const std::string& answer) {
    c.phase = Phase::Answer;
    c.to_upstream.clear();
    c.to_client = answer;
    c.deadline = Clock::now() + kAnswerTimeout;
}

void ForwardRelay::new_log_window(Clock::time_point now) {
    if (now - log_window_ < std::chrono::seconds(1))
        return;
    if (unlogged_ > 0)
        std::fprintf(stderr, "caracaractl: %d more connections to localhost:%u refused\n", unlogged_, port_);
    log_window_ = now;
    logged_ = unlogged_ = 0;
}

void ForwardRelay::on_head(Conn& c) {
    const std::string_view head(c.to_upstream.data(), c.to_upstream.find("\r\n\r\n") + 4);
    const ForwardKey::Judgement j = key_.judge(head);
    if (j.verdict != ForwardKey::Verdict::Relay) {
        if (j.verdict != ForwardKey::Verdict::Redirect) {
            std::string origin = j.origin;
            for (char& ch : origin)
                ch = (ch < 0x20 || ch > 0x7e) ? '?' : ch;
            const char* why = j.verdict == ForwardKey::Verdict::NoKey    ? "without the key"
                              : j.verdict == ForwardKey::Verdict::WrongKey ? "with a wrong key"
                                                                           : "not an HTTP request";
            new_log_window(Clock::now());
            if (++logged_ <= kRefusalsLoggedPerSecond)
                std::fprintf(stderr, "caracaractl: refused a connection to localhost:%u %s%s%s%s; nothing was relayed\n",
                             port_, why, origin.empty() ? "" : " (from a page of ", origin.c_str(), origin.empty() ? "" : ")");
            else
                ++unlogged_;
        }
        return refuse(c, key_.answer(j));
    }
    c.upstream = ::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::strncpy(a.sun_path, upstream_.c_str(), sizeof a.sun_path - 1);
    if (c.upstream < 0 || ::connect(c.upstream, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
        const std::string why = std::strerror(errno);
        if (c.upstream >= 0)
            ::close(c.upstream);
        c.upstream = -1;
        std::fprintf(stderr, "caracaractl: the forward's socket: %s\n", why.c_str());
        return refuse(c, status_answer("502 Bad Gateway", "caracaractl: the SSH forward to the vehicle is not there: " +
                                                              why + "\n"));
    }
    c.phase = Phase::Relay; // the head (and whatever came after it) goes first
}

bool ForwardRelay::step(Conn& c, short cev, short uev) {
    const auto now = Clock::now();
    switch (c.phase) {
    case Phase::Head:
        if (cev & (POLLIN | POLLHUP | POLLERR)) {
            if (!read_into(c.client, c.to_upstream, kMaxHead))
                return false; // gone before its request
            if (c.to_upstream.find("\r\n\r\n") != std::string::npos)
                on_head(c);
            else if (c.to_upstream.size() >= kMaxHead)
                refuse(c, status_answer("431 Request Header Fields Too Large", "caracaractl: the request head is too large\n"));
        }
        if (c.phase != Phase::Head)
            return step(c, 0, 0); // the answer, or the head to the vehicle, goes now
        return now < c.deadline;  // else no request in time
    case Phase::Answer: {
        if (!write_from(c.client, c.to_client))
            return false;
        if (c.to_client.empty() && !c.client_shut) {
            // Read what the client still sends until it closes, so the close is no reset that
            // could take the answer with it.
            ::shutdown(c.client, SHUT_WR);
            c.client_shut = true;
        }
        if (cev & (POLLIN | POLLHUP | POLLERR)) {
            std::string discard;
            if (!read_into(c.client, discard, kMaxHead))
                return false;
        }
        return now < c.deadline;
    }
    case Phase::Relay:
        break;
    }
    if ((cev & (POLLIN | POLLHUP | POLLERR)) && !c.client_eof)
        c.client_eof = !read_into(c.client, c.to_upstream, kMaxBuffered);
    if ((uev & (POLLIN | POLLHUP | POLLERR)) && !c.upstream_eof)
        c.upstream_eof = !read_into(c.upstream, c.to_client, kMaxBuffered);
    if (!write_from(c.client, c.to_client) || !write_from(c.upstream, c.to_upstream))
        return false;
    if (c.client_eof && c.to_upstream.empty() && !c.upstream_shut) {
        ::shutdown(c.upstream, SHUT_WR);
        c.upstream_shut = true;
    }
    if (c.upstream_eof && c.to_client.empty() && !c.client_shut) {
        ::shutdown(c.client, SHUT_WR);
        c.client_shut = true;
        c.deadline = now + kAnswerTimeout; // the vehicle's side is done: the client has this long to close
    }
    if (c.client_shut && c.upstream_shut)
        return false;
    return !(c.client_shut && now >= c.deadline);
}

void ForwardRelay::run_once(int timeout_ms, bool accepting) {
    std::vector<pollfd> fds;
    std::vector<std::pair<int, int>> at; // each connection's client and upstream entries in fds (-1: none)
    auto now = Clock::now();
    if (unlogged_ > 0)
        new_log_window(now);
    if (accepting)
        fds.push_back({listen_fd_, POLLIN, 0});
    for (const Conn& c : conns_) {
        short cev = 0, uev = 0;
        switch (c.phase) {
        case Phase::Head:
            cev = POLLIN;
            break;
        case Phase::Answer:
            cev = static_cast<short>(c.to_client.empty() ? POLLIN : POLLOUT);
            break;
        case Phase::Relay:
            cev = static_cast<short>((!c.client_eof && c.to_upstream.size() < kMaxBuffered ? POLLIN : 0) |
                                     (!c.to_client.empty() ? POLLOUT : 0));
            uev = static_cast<short>((!c.upstream_eof && c.to_client.size() < kMaxBuffered ? POLLIN : 0) |
                                     (!c.to_upstream.empty() ? POLLOUT : 0));
            break;
        }
        if (c.phase != Phase::Relay || c.client_shut) {
            const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(c.deadline - now).count();
            timeout_ms = static_cast<int>(std::clamp<long long>(left + 1, 0, timeout_ms));
        }
        // A side with nothing to wait for is left out (a negative fd): a socket whose peer has
        // closed reports POLLHUP whatever is asked, and would wake this loop until the other side ends.
        at.emplace_back(static_cast<int>(fds.size()), c.upstream >= 0 ? static_cast<int>(fds.size()) + 1 : -1);
        fds.push_back({cev ? c.client : -1, cev, 0});
        if (c.upstream >= 0)
            fds.push_back({uev ? c.upstream : -1, uev, 0});
    }
    if (::poll(fds.data(), fds.size(), timeout_ms) < 0 && errno != EINTR)
        return;
    std::size_t i = 0;
    for (auto it = conns_.begin(); it != conns_.end(); ++i) {
        const short cev = fds[static_cast<std::size_t>(at[i].first)].revents;
        const short uev = at[i].second >= 0 ? fds[static_cast<std::size_t>(at[i].second)].revents : 0;
        if (step(*it, cev, uev)) {
            ++it;
        } else {
            close_conn(*it);
            it = conns_.erase(it);
        }
    }
    if (accepting && (fds[0].revents & POLLIN))
        accept_all();
}

} // namespace caracara::ctl
