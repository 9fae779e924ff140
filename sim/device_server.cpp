#include "sim/device_server.hpp"

#include "protocol/sim_protocol.hpp"

#include <cerrno>
#include <cstring>
#include <ctime>
#include <linux/i2c-dev.h>
#include <linux/i2c.h>
#include <linux/spi/spidev.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

namespace caracara::sim {

using simproto::Op;

namespace {
// What an i2c-dev adapter like i2c-bcm2835 advertises.
constexpr unsigned long kI2cFuncs = I2C_FUNC_I2C | I2C_FUNC_SMBUS_EMUL;
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

DeviceServer::DeviceServer(sd_event* event, SimVehicle& vehicle) : event_(event), vehicle_(vehicle) {
    // The default timer slack (50 us) would eat half of wait_until's spun tail.
    ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
    vehicle_.gpio().on_change = [this](int line, int value, uint64_t when_ns) { push_gpio_event(line, value, when_ns); };
}

void DeviceServer::push_gpio_event(int line, int value, uint64_t when_ns) {
    uint8_t buf[32];
    for (auto& [key, c] : clients_) {
        if (c->watched_line != line)
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
    // Like the kernel, a process that goes away releases its GPIO lines.
    for (auto& [h, line] : c->gpio_lines)
        vehicle_.gpio().release(line, monotonic_ns());
    ::close(c->fd);
    clients_.erase(c); // destroys the event sources with the client
}

int DeviceServer::on_client(sd_event_source*, int fd, uint32_t revents, void* userdata) {
    auto* c = static_cast<Client*>(userdata);
    DeviceServer* self = c->server;
    uint8_t buf[simproto::kMaxMessage];
    ssize_t n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT);
    if (n < 0 && (errno == EAGAIN || errno == EINTR))
        return 0;
    if (n <= 0 || (revents & (EPOLLHUP | EPOLLERR) && n <= 0)) {
        self->drop(c);
        return 0;
    }
    const uint64_t wire_ns = self->handle(*c, {buf, static_cast<size_t>(n)});
    if (!self->vehicle_.realistic_timing() || wire_ns == 0) {
        self->send_reply(*c);
        return 0;
    }
    // Realistic timing: the reply leaves when the transaction is over on the wire, and the
    // wire is shared, so a transaction waits for the one before it.
    uint64_t& free_at = self->vehicle_.bus_free_at();
    free_at = self->vehicle_.wire_start(monotonic_ns()) + wire_ns;
    if (free_at - monotonic_ns() <= kSpinLimitNs) {
        // Short waits block the simulator right here: an event-loop timer would add its own
        // wake-up lateness to every order.
        wait_until(free_at);
        self->send_reply(*c);
        return 0;
    }
    sd_event_source_set_enabled(c->io.get(), SD_EVENT_OFF);
    sd_event_source* t = nullptr;
    if (sd_event_add_time(self->event_, &t, CLOCK_MONOTONIC, free_at / 1000, 1, on_reply_due, c) < 0) {
        self->send_reply(*c);
        sd_event_source_set_enabled(c->io.get(), SD_EVENT_ON);
        return 0;
    }
    c->reply_timer.reset(t);
    return 0;
}

int DeviceServer::on_reply_due(sd_event_source*, uint64_t, void* userdata) {
    auto* c = static_cast<Client*>(userdata);
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

uint64_t DeviceServer::handle(Client& c, std::span<const uint8_t> req) {
    simproto::Reader r(req);
    simproto::Header h;
    simproto::Writer w(c.reply);
    // Header and result go first, then the payload; the buffer is trimmed to what was written.
    auto finish = [&](int) { c.reply_len = w.size(); };
    if (!r.header(h) || (h.op & simproto::kReplyBit)) {
        ++bad_requests_;
        // Not even a header we understand: answer with a bare error so the client is not left hanging.
        w.header(static_cast<Op>(h.op & ~simproto::kReplyBit), h.seq, true);
        w.i32(-EBADMSG);
        finish(-EBADMSG);
        return 0;
    }
    const Op op = static_cast<Op>(h.op);
    auto begin = [&](int result) {
        w.header(op, h.seq, true);
        w.i32(result);
    };
    auto bad = [&](int err) {
        ++bad_requests_;
        w = simproto::Writer(c.reply);
        begin(err);
        finish(err);
        return uint64_t{0};
    };
    switch (op) {
    case Op::Open: {
        auto path = r.str(4096);
        r.i32(); // flags: the simulated nodes ignore O_* like a char device mostly does
        if (!r.ok() || !r.at_end())
            return bad(-EBADMSG);
        auto kind = vehicle_.node_kind(std::string(path), monotonic_ns());
        if (kind == SimVehicle::NodeKind::None)
            return bad(-ENOENT);
        int hnd = c.next_handle++;
        c.handles[hnd] = {kind, std::string(path)};
        begin(hnd);
        finish(hnd);
        return 0;
    }
    case Op::Close: {
        int32_t hnd = r.i32();
        if (!r.ok() || !r.at_end())
            return bad(-EBADMSG);
        if (!c.handles.erase(hnd))
            return bad(-EBADF);
        begin(0);
        finish(0);
        return 0;
    }
    case Op::I2cRdwr: {
        int32_t hnd = r.i32();
        uint32_t n = r.u32();
        if (!r.ok())
            return bad(-EBADMSG);
        auto it = c.handles.find(hnd);
        if (it == c.handles.end())
            return bad(-EBADF);
        if (it->second.kind != SimVehicle::NodeKind::I2c)
            return bad(-ENOTTY);
        if (n == 0 || n > I2C_RDWR_IOCTL_MAX_MSGS)
            return bad(-EINVAL);
        if (!vehicle_.i2c_present(monotonic_ns()))
            return bad(-ENODEV); // the adapter was unbound under an open file
        std::vector<I2cMessage> msgs(n);
        for (auto& m : msgs) {
            m.addr = r.u16();
            m.flags = r.u16();
            uint16_t len = r.u16();
            if (!r.ok() || len > 8192)
                return bad(-EBADMSG);
            if (m.flags & I2C_M_RD)
                m.data.assign(len, 0);
            else {
                auto b = r.bytes(len);
                m.data.assign(b.begin(), b.end());
            }
        }
        if (!r.ok() || !r.at_end())
            return bad(-EBADMSG);
        const uint64_t start = vehicle_.wire_start(monotonic_ns());
        auto res = vehicle_.i2c().transfer(msgs, start);
        begin(res.ret);
        if (res.ret >= 0)
            for (auto& m : msgs)
                if (m.flags & I2C_M_RD)
                    w.bytes(m.data.data(), m.data.size());
        finish(res.ret);
        return res.wire_ns;
    }
    case Op::SpiMessage: {
        int32_t hnd = r.i32();
        uint32_t n = r.u32();
        if (!r.ok())
            return bad(-EBADMSG);
        auto it = c.handles.find(hnd);
        if (it == c.handles.end())
            return bad(-EBADF);
        if (it->second.kind != SimVehicle::NodeKind::Spi)
            return bad(-ENOTTY);
        if (n > 512)
            return bad(-EINVAL);
        std::vector<SpiMessageXfer> xfers(n);
        size_t total = 0;
        for (auto& x : xfers) {
            x.len = r.u32();
            x.params.speed_hz = r.u32();
            x.params.delay_usecs = r.u16();
            x.params.bits_per_word = r.u8();
            x.params.cs_change = r.u8() != 0;
            const bool has_tx = r.u8() != 0;
            x.want_rx = r.u8() != 0;
            total += x.len;
            if (!r.ok() || total > 8192)
                return bad(-EBADMSG);
            if (has_tx) {
                auto b = r.bytes(x.len);
                x.tx.assign(b.begin(), b.end());
            }
        }
        if (!r.ok() || !r.at_end())
            return bad(-EBADMSG);
        SpiPort* port = vehicle_.spi_port(it->second.path);
        const uint64_t start = vehicle_.wire_start(monotonic_ns());
        uint64_t wire = 0;
        int res = vehicle_.spi_message(*port, xfers, start, wire);
        begin(res);
        for (auto& x : xfers)
            if (x.want_rx)
                w.bytes(x.rx.data(), x.rx.size());
        finish(res);
        return wire;
    }
    case Op::Ioctl: {
        int32_t hnd = r.i32();
        uint64_t request = r.u64();
        uint64_t value = r.u64();
        if (!r.ok() || !r.at_end())
            return bad(-EBADMSG);
        auto it = c.handles.find(hnd);
        if (it == c.handles.end())
            return bad(-EBADF);
        uint64_t out = 0;
        int result = 0;
        if (it->second.kind == SimVehicle::NodeKind::Unbind || it->second.kind == SimVehicle::NodeKind::Bind) {
            result = -ENOTTY;
        } else if (it->second.kind == SimVehicle::NodeKind::I2c) {
            switch (request) {
            case I2C_FUNCS: out = kI2cFuncs; break;
            case I2C_TIMEOUT:
            case I2C_RETRIES:
            case I2C_SLAVE:
            case I2C_SLAVE_FORCE: break;
            default: result = -ENOTTY;
            }
        } else {
            SpiPort* p = vehicle_.spi_port(it->second.path);
            switch (request) {
            case SPI_IOC_WR_MODE: p->mode = static_cast<uint8_t>(value); break;
            case SPI_IOC_RD_MODE: out = p->mode; break;
            case SPI_IOC_WR_BITS_PER_WORD: p->bits_per_word = static_cast<uint8_t>(value); break;
            case SPI_IOC_RD_BITS_PER_WORD: out = p->bits_per_word; break;
            case SPI_IOC_WR_MAX_SPEED_HZ:
                if (value == 0) result = -EINVAL; else p->max_speed_hz = static_cast<uint32_t>(value);
                break;
            case SPI_IOC_RD_MAX_SPEED_HZ: out = p->max_speed_hz; break;
            case SPI_IOC_WR_LSB_FIRST: p->lsb_first = static_cast<uint8_t>(value); break;
            case SPI_IOC_RD_LSB_FIRST: out = p->lsb_first; break;
            case SPI_IOC_WR_MODE32: p->mode = static_cast<uint8_t>(value & 0xFF); break;
            case SPI_IOC_RD_MODE32: out = p->mode; break;
            default: result = -ENOTTY;
            }
        }
        if (result < 0)
            return bad(result);
        begin(result);
        w.u64(out);
        finish(result);
        return 0;
    }
    case Op::Write: {
        int32_t hnd = r.i32();
        uint32_t n = r.u32();
        auto data = r.bytes(n);
        if (!r.ok() || !r.at_end())
            return bad(-EBADMSG);
        auto it = c.handles.find(hnd);
        if (it == c.handles.end())
            return bad(-EBADF);
        if (it->second.kind != SimVehicle::NodeKind::Unbind && it->second.kind != SimVehicle::NodeKind::Bind)
            return bad(-EINVAL);
        int res = vehicle_.sysfs_write(it->second.kind,
                                       {reinterpret_cast<const char*>(data.data()), data.size()}, monotonic_ns());
        begin(res);
        finish(res);
        return 0;
    }
    case Op::GpioRequest: {
        auto chip = std::string(r.str(256));
        auto name = std::string(r.str(256));
        int32_t offset = r.i32();
        uint8_t mode = r.u8();
        uint8_t active_low = r.u8();
        uint8_t initial = r.u8();
        if (!r.ok() || !r.at_end() || mode > static_cast<uint8_t>(GpioMode::OpenDrain))
            return bad(-EBADMSG);
        int line = vehicle_.gpio().find(chip, name, offset);
        if (line < 0)
            return bad(line);
        int res = vehicle_.gpio().request(line, static_cast<GpioMode>(mode), active_low, initial, monotonic_ns());
        if (res < 0)
            return bad(res);
        int hnd = c.next_handle++;
        c.gpio_lines[hnd] = line;
        begin(hnd);
        finish(hnd);
        return 0;
    }
    case Op::GpioGet:
    case Op::GpioSet:
    case Op::GpioRelease: {
        int32_t hnd = r.i32();
        uint8_t value = op == Op::GpioSet ? r.u8() : 0;
        if (!r.ok() || !r.at_end())
            return bad(-EBADMSG);
        auto it = c.gpio_lines.find(hnd);
        if (it == c.gpio_lines.end())
            return bad(-EBADF);
        int res = 0;
        if (op == Op::GpioGet)
            res = vehicle_.gpio().get(it->second);
        else if (op == Op::GpioSet)
            res = vehicle_.gpio().set(it->second, value, monotonic_ns());
        else {
            vehicle_.gpio().release(it->second, monotonic_ns());
            c.gpio_lines.erase(it);
        }
        begin(res);
        finish(res);
        return 0;
    }
    case Op::GpioWatch: {
        auto chip = std::string(r.str(256));
        auto name = std::string(r.str(256));
        int32_t offset = r.i32();
        if (!r.ok() || !r.at_end())
            return bad(-EBADMSG);
        int line = vehicle_.gpio().find(chip, name, offset);
        if (line < 0)
            return bad(line);
        c.watched_line = line;
        begin(0);
        finish(0);
        return 0;
    }
    case Op::GpioEvent:
        break;
    }
    return bad(-EBADMSG); // unknown op
}

} // namespace caracara::sim
