#include "drivers/platform/sim/sim_connection.hpp"

#include <poll.h>

#include <cerrno>
#include <cstring>
#include <sys/socket.h>
#include <sys/time.h>
#include <sys/un.h>
#include <unistd.h>

namespace caracara {

using simproto::Op;
using simproto::Reader;
using simproto::Writer;

namespace {
// A simulator that stops answering looks to the driver like a controller timeout.
constexpr int kReplyTimeoutMs = 2000;
} // namespace

SimConnection::~SimConnection() {
    if (sock_ >= 0)
        ::close(sock_);
}

int SimConnection::connect(const std::string& socket_path) {
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    if (socket_path.size() >= sizeof(addr.sun_path))
        return -ENAMETOOLONG;
    std::memcpy(addr.sun_path, socket_path.c_str(), socket_path.size() + 1);
    int s = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
    if (s < 0)
        return -errno;
    timeval tv{kReplyTimeoutMs / 1000, (kReplyTimeoutMs % 1000) * 1000};
    ::setsockopt(s, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    if (::connect(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) {
        int e = errno;
        ::close(s);
        return -e;
    }
    sock_ = s;
    path_ = socket_path;
    return 0;
}

int SimConnection::roundtrip(size_t len, Op op, Reader& payload) {
    if (sock_ < 0)
        return -ENODEV;
    ssize_t n;
    do {
        n = ::send(sock_, tx_.data(), len, MSG_NOSIGNAL);
    } while (n < 0 && errno == EINTR);
    if (n < 0) {
        if (errno != EPIPE && errno != ECONNRESET)
            return -errno;
        drop();
        return -ENODEV;
    }
    const uint32_t want_seq = seq_;
    for (;;) {
        do {
            n = ::recv(sock_, rx_.data(), rx_.size(), 0);
        } while (n < 0 && errno == EINTR);
        if (n == 0 || (n < 0 && errno == ECONNRESET)) {
            drop(); // the simulator went away: the adapter is gone
            return -ENODEV;
        }
        if (n < 0)
            return errno == EAGAIN || errno == EWOULDBLOCK ? -ETIMEDOUT : -errno;
        Reader r({rx_.data(), static_cast<size_t>(n)});
        simproto::Header h;
        if (!r.header(h))
            return -EPROTO;
        if (h.seq != want_seq)
            continue; // a late reply to a request we already gave up on
        if (h.op != (static_cast<uint16_t>(op) | simproto::kReplyBit))
            return -EPROTO;
        int32_t result = r.i32();
        if (!r.ok())
            return -EPROTO;
        payload = r;
        return result;
    }
}

void SimConnection::drop() {
    if (sock_ >= 0)
        ::close(sock_);
    sock_ = -1;
}

int SimConnection::reconnect_if_gone() {
    if (sock_ >= 0)
        return 0;
    if (path_.empty())
        return -ENODEV;
    if (connect(path_) < 0)
        return -ENODEV;
    // Handles of the old connection name nothing on the new one.
    generation_ = generation_ % kMaxGeneration + 1;
    return 0;
}

int SimConnection::wire_handle(int fd) const {
    if (fd < 0 || (fd >> kGenerationShift) != generation_)
        return -1;
    return fd & ((1 << kGenerationShift) - 1);
}

int SimConnection::tagged(int handle) const {
    if (handle < 0 || handle >= (1 << kGenerationShift))
        return handle < 0 ? handle : -EMFILE;
    return (generation_ << kGenerationShift) | handle;
}

bool SimConnection::gpio_set_in_signal_handler(int line, int value) noexcept {
    const int h = wire_handle(line);
    if (h < 0 || sock_ < 0)
        return false;
    std::array<uint8_t, 32> buf{};
    Writer w(buf);
    w.header(Op::GpioSet, 0);
    w.i32(h);
    w.u8(value ? 1 : 0);
    const int saved = errno;
    bool ok = w.ok() && ::send(sock_, buf.data(), w.size(), MSG_NOSIGNAL | MSG_DONTWAIT) > 0;
    // Wait (at most 50 ms) for its reply: the simulator has then set the line, before anything
    // the caller sends next on another connection (the emergency stop's zero orders). Another
    // thread may take the reply first; then the bound ends the wait.
    for (int waited_ms = 0; ok && waited_ms < 50; ++waited_ms) {
        pollfd p{sock_, POLLIN, 0};
        if (::poll(&p, 1, 1) <= 0)
            continue;
        std::array<uint8_t, 64> rx{};
        const ssize_t n = ::recv(sock_, rx.data(), rx.size(), MSG_DONTWAIT);
        Reader r({rx.data(), n > 0 ? static_cast<size_t>(n) : 0});
        simproto::Header reply;
        if (n > 0 && r.header(reply) && reply.seq == 0)
            break;
    }
    errno = saved;
    return ok;
}

} // namespace caracara
