#include "sim/device_server.hpp"

#include "drivers/protocol/sim_protocol.hpp"

#include <cerrno>
#include <cstring>
#include <vector>
#include <ctime>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

namespace caracara::sim {

using simproto::Op;

namespace {
constexpr uint64_t kSpinLimitNs = 2'000'000;
// The last part of a short wait is spun; the rest is slept (see wait_until).
constexpr uint64_t kSpinTailNs = 100'000;

// Waits until the monotonic clock reaches `deadline_ns`. A wake-up on a busy VM can come tens of
// microseconds late, a good part of a 380 us order, so the end of the wait is spun; sleeping
// through the rest keeps the simulated wire from taking a whole CPU away from the processes it
// serves, which the vehicle's I2C controller does not do either.
void wait_until(uint64_t deadline_ns) {
    if (deadline_ns > monotonic_ns() + kSpinTailNs) {
        const uint64_t wake = deadline_ns - kSpinTailNs;
        timespec ts{static_cast<time_t>(wake / 1'000'000'000ull), static_cast<long>(wake % 1'000'000'000ull)};
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
        }
    }
    while (monotonic_ns() < deadline_ns) {
    }
}
} // namespace

DeviceServer::DeviceServer(sd_event* event, SimVehicle& vehicle) : event_(event), vehicle_(vehicle), ops_(vehicle) {
    // The default timer slack (50 us) would eat half of wait_until's spun tail.
    ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
    vehicle_.gpio().on_change = [this](int line, int value, uint64_t when_ns) { push_gpio_event(line, value, when_ns); };
    // A line gone: its edge watchers' connections end, as a removed chip's event fd hangs up.
    vehicle_.gpio().on_gone = [this](int line) {
        std::vector<Client*> watchers;
        for (auto& [key, c] : clients_)
            if (c->session.watched_line == line)
                watchers.push_back(key);
        for (Client* c : watchers)
            drop(c);
    };
}

void DeviceServer::push_gpio_event(int line, int value, uint64_t when_ns) {
    uint8_t buf[32];
    for (auto& [key, c] : clients_) {
        if (c->session.watched_line != line)
            continue;
        simproto::Writer w(buf);
        w.header(Op::GpioEvent, 0, true);
        w.i32(value);
        w.u64(when_ns); // the stamp of the change, as in the wire log
        ::send(c->fd, buf, w.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    }
}

DeviceServer::~DeviceServer() {
    vehicle_.gpio().on_change = nullptr;
    vehicle_.gpio().on_gone = nullptr;
    clients_.clear();
    accept_source_.reset();
    if (listen_fd_ >= 0) {
        ::close(listen_fd_);
        ::unlink(path_.c_str());
    }
}

int DeviceServer::listen(const std::string& path) {
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    if (path.size() >= sizeof addr.sun_path)
        return -ENAMETOOLONG;
    std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
    int fd = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    if (fd < 0)
        return -errno;
    ::unlink(path.c_str());
    if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0 || ::listen(fd, 16) < 0) {
        int e = errno;
        ::close(fd);
        return -e;
    }
    listen_fd_ = fd;
    path_ = path;
    sd_event_source* s = nullptr;
    int r = sd_event_add_io(event_, &s, fd, EPOLLIN, on_accept, this);
    if (r < 0)
        return r;
    accept_source_.reset(s);
    return 0;
}

int DeviceServer::on_accept(sd_event_source*, int fd, uint32_t, void* userdata) {
    auto* self = static_cast<DeviceServer*>(userdata);
    int cfd = ::accept4(fd, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
    if (cfd < 0)
        return 0;
    auto c = std::make_unique<Client>();
    c->server = self;
    c->fd = cfd;
    sd_event_source* s = nullptr;
    if (sd_event_add_io(self->event_, &s, cfd, EPOLLIN, on_client, c.get()) < 0) {
        ::close(cfd);
        return 0;
    }
    c->io.reset(s);
    Client* key = c.get();
    self->clients_[key] = std::move(c);
    return 0;
}

void DeviceServer::drop(Client* c) {
    ops_.release(c->session);
    ::close(c->fd);
    clients_.erase(c); // destroys the event sources with the client
}

int DeviceServer::on_client(sd_event_source*, int fd, uint32_t revents, void* userdata) {
    auto* c = static_cast<Client*>(userdata);
    DeviceServer* self = c->server;
    uint8_t buf[simproto::kMaxMessage];
    // MSG_TRUNC: the real length of a longer message, whose rest the socket discards.
    ssize_t n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT | MSG_TRUNC);
    if (n < 0 && (errno == EAGAIN || errno == EINTR))
        return 0;
    if (n <= 0 || (revents & (EPOLLHUP | EPOLLERR) && n <= 0)) {
        self->drop(c);
        return 0;
    }
    uint64_t wire_ns = 0;
    const bool truncated = static_cast<size_t>(n) > sizeof buf;
    c->reply_len = self->ops_.handle(c->session, {buf, truncated ? sizeof buf : static_cast<size_t>(n)}, c->reply,
                                     wire_ns, truncated);
    uint64_t due_ns = 0;
    if (self->vehicle_.realistic_timing() && wire_ns > 0) {
        // Realistic timing: the reply leaves when the transaction is over on the wire, and the
        // wire is shared, so a transaction waits for the one before it on the same bus.
        const bool spi = self->ops_.last_on_spi();
        uint64_t& free_at = spi ? self->vehicle_.spi_free_at() : self->vehicle_.bus_free_at();
        free_at = (spi ? self->vehicle_.spi_wire_start(monotonic_ns()) : self->vehicle_.wire_start(monotonic_ns())) + wire_ns;
        due_ns = free_at;
    } else if (const uint64_t held = self->ops_.last_held_ns(); held > 0) {
        due_ns = monotonic_ns() + held; // a hung device holds the transfer in any timing mode
    } else {
        self->send_reply(*c);
        return 0;
    }
    // Only the spun tail of a wait blocks the simulator: the other clients (the GPIO lines'
    // connection, the other bus) are served meanwhile, as the kernel serves a GPIO ioctl while
    // an I2C transfer is on the wire. The timer fires early by the tail, which absorbs its
    // wake-up lateness.
    if (due_ns <= monotonic_ns() + kSpinTailNs) {
        wait_until(due_ns);
        self->send_reply(*c);
        return 0;
    }
    c->due_ns = due_ns;
    sd_event_source_set_enabled(c->io.get(), SD_EVENT_OFF);
    sd_event_source* t = nullptr;
    const uint64_t wake_ns = due_ns - (due_ns - monotonic_ns() <= kSpinLimitNs ? kSpinTailNs : 0);
    if (sd_event_add_time(self->event_, &t, CLOCK_MONOTONIC, wake_ns / 1000, 1, on_reply_due, c) < 0) {
        wait_until(due_ns);
        self->send_reply(*c);
        sd_event_source_set_enabled(c->io.get(), SD_EVENT_ON);
        return 0;
    }
    c->reply_timer.reset(t);
    return 0;
}

int DeviceServer::on_reply_due(sd_event_source*, uint64_t, void* userdata) {
    auto* c = static_cast<Client*>(userdata);
    if (c->due_ns - monotonic_ns() <= kSpinTailNs)
        wait_until(c->due_ns); // the spun tail (nothing to spin when the timer came late)
    c->server->send_reply(*c);
    sd_event_source_set_enabled(c->io.get(), SD_EVENT_ON);
    c->reply_timer.reset();
    return 0;
}

void DeviceServer::send_reply(Client& c) {
    if (::send(c.fd, c.reply.data(), c.reply_len, MSG_NOSIGNAL | MSG_DONTWAIT) < 0) {
        // The client went away; its hangup is handled by the io source.
    }
}

} // namespace caracara::sim
