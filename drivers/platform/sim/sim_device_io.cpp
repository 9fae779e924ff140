#include "drivers/platform/sim/sim_device_io.hpp"

#include <poll.h>

#include <cerrno>
#include <cstring>
#include <linux/i2c-dev.h>
#include <linux/i2c.h>
#include <linux/spi/spidev.h>
#include <sys/ioctl.h>
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

SimDeviceIo::~SimDeviceIo() {
    if (sock_ >= 0)
        ::close(sock_);
}

int SimDeviceIo::connect(const std::string& socket_path) {
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

int SimDeviceIo::roundtrip(size_t len, Op op, Reader& payload) {
    if (sock_ < 0)
        return -ENODEV;
    ssize_t n;
    do {
        n = ::send(sock_, tx_.data(), len, MSG_NOSIGNAL);
    } while (n < 0 && errno == EINTR);
    if (n < 0) {
        if (errno != EPIPE && errno != ECONNRESET)
            return -errno;
        drop_connection();
        return -ENODEV;
    }
    const uint32_t want_seq = seq_;
    for (;;) {
        do {
            n = ::recv(sock_, rx_.data(), rx_.size(), 0);
        } while (n < 0 && errno == EINTR);
        if (n == 0 || (n < 0 && errno == ECONNRESET)) {
            drop_connection(); // the simulator went away: the adapter is gone
            return -ENODEV;
        }
        if (n < 0)
            return errno == EAGAIN || errno == EWOULDBLOCK ? -ETIMEDOUT : -errno;
        rx_len_ = static_cast<size_t>(n);
        Reader r({rx_.data(), rx_len_});
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

void SimDeviceIo::drop_connection() {
    if (sock_ >= 0)
        ::close(sock_);
    sock_ = -1;
}

int SimDeviceIo::reconnect_if_gone() {
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

int SimDeviceIo::wire_handle(int fd) const {
    if (fd < 0 || (fd >> kGenerationShift) != generation_)
        return -1;
    return fd & ((1 << kGenerationShift) - 1);
}

int SimDeviceIo::tagged(int handle) const {
    if (handle < 0 || handle >= (1 << kGenerationShift))
        return handle < 0 ? handle : -EMFILE;
    return (generation_ << kGenerationShift) | handle;
}

int SimDeviceIo::open(const char* path, int flags) {
    if (reconnect_if_gone() < 0)
        return -ENODEV;
    Writer w(tx_);
    w.header(Op::Open, ++seq_);
    w.str(path);
    w.i32(flags);
    if (!w.ok())
        return -ENAMETOOLONG;
    Reader r({});
    return tagged(roundtrip(w.size(), Op::Open, r));
}

int SimDeviceIo::close(int fd) {
    const int h = wire_handle(fd);
    if (h < 0)
        return -ENODEV; // made on a connection that is gone
    Writer w(tx_);
    w.header(Op::Close, ++seq_);
    w.i32(h);
    Reader r({});
    return roundtrip(w.size(), Op::Close, r);
}

int SimDeviceIo::write(int fd, const void* buf, size_t len) {
    const int h = wire_handle(fd);
    if (h < 0)
        return -ENODEV; // made on a connection that is gone
    Writer w(tx_);
    w.header(Op::Write, ++seq_);
    w.i32(h);
    w.u32(static_cast<uint32_t>(len));
    w.bytes(buf, len);
    if (!w.ok())
        return -EMSGSIZE;
    Reader r({});
    return roundtrip(w.size(), Op::Write, r);
}

int SimDeviceIo::gpio_request(const std::string& chip, const std::string& name, int offset, simproto::GpioMode mode,
                              bool active_low, int initial) {
    if (reconnect_if_gone() < 0)
        return -ENODEV;
    Writer w(tx_);
    w.header(Op::GpioRequest, ++seq_);
    w.str(chip);
    w.str(name);
    w.i32(offset);
    w.u8(static_cast<uint8_t>(mode));
    w.u8(active_low ? 1 : 0);
    w.u8(initial ? 1 : 0);
    if (!w.ok())
        return -ENAMETOOLONG;
    Reader r({});
    return tagged(roundtrip(w.size(), Op::GpioRequest, r));
}

int SimDeviceIo::simple(Op op, int32_t a, int32_t b) {
    const int h = wire_handle(a);
    if (h < 0)
        return -ENODEV;
    Writer w(tx_);
    w.header(op, ++seq_);
    w.i32(h);
    if (op == Op::GpioSet)
        w.u8(b ? 1 : 0);
    Reader r({});
    return roundtrip(w.size(), op, r);
}

bool SimDeviceIo::gpio_set_in_signal_handler(int line, int value) noexcept {
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

int SimDeviceIo::gpio_get(int line) { return simple(Op::GpioGet, line); }
int SimDeviceIo::gpio_set(int line, int value) { return simple(Op::GpioSet, line, value); }
int SimDeviceIo::gpio_release(int line) { return simple(Op::GpioRelease, line); }

int SimDeviceIo::ioctl(int fd, unsigned long request, void* arg) {
    fd = wire_handle(fd);
    if (fd < 0)
        return -ENODEV; // made on a connection that is gone
    if (request == I2C_RDWR)
        return i2c_rdwr(fd, arg);
    if (_IOC_TYPE(request) == SPI_IOC_MAGIC && _IOC_NR(request) == 0 && _IOC_DIR(request) == _IOC_WRITE)
        return spi_message(fd, request, arg);
    return small_ioctl(fd, request, arg);
}

int SimDeviceIo::i2c_rdwr(int fd, void* arg) {
    auto* data = static_cast<i2c_rdwr_ioctl_data*>(arg);
    if (!data || !data->msgs || data->nmsgs == 0 || data->nmsgs > I2C_RDWR_IOCTL_MAX_MSGS)
        return -EINVAL; // as i2cdev_ioctl_rdwr does
    Writer w(tx_);
    w.header(Op::I2cRdwr, ++seq_);
    w.i32(fd);
    w.u32(data->nmsgs);
    for (uint32_t i = 0; i < data->nmsgs; ++i) {
        const i2c_msg& m = data->msgs[i];
        w.u16(m.addr);
        w.u16(m.flags);
        w.u16(m.len);
        if (!(m.flags & I2C_M_RD))
            w.bytes(m.buf, m.len);
    }
    if (!w.ok())
        return -EMSGSIZE;
    Reader r({});
    int result = roundtrip(w.size(), Op::I2cRdwr, r);
    if (result < 0)
        return result;
    for (uint32_t i = 0; i < data->nmsgs; ++i) {
        i2c_msg& m = data->msgs[i];
        if (!(m.flags & I2C_M_RD))
            continue;
        auto b = r.bytes(m.len);
        if (!r.ok())
            return -EPROTO;
        std::memcpy(m.buf, b.data(), b.size());
    }
    return result;
}

int SimDeviceIo::spi_message(int fd, unsigned long request, void* arg) {
    const size_t n = _IOC_SIZE(request) / sizeof(spi_ioc_transfer);
    if (_IOC_SIZE(request) % sizeof(spi_ioc_transfer) != 0)
        return -EINVAL;
    auto* xfers = static_cast<spi_ioc_transfer*>(arg);
    if (!xfers && n)
        return -EFAULT;
    Writer w(tx_);
    w.header(Op::SpiMessage, ++seq_);
    w.i32(fd);
    w.u32(static_cast<uint32_t>(n));
    for (size_t i = 0; i < n; ++i) {
        const spi_ioc_transfer& t = xfers[i];
        w.u32(t.len);
        w.u32(t.speed_hz);
        w.u16(t.delay_usecs);
        w.u8(t.bits_per_word);
        w.u8(t.cs_change);
        w.u8(t.tx_buf ? 1 : 0);
        w.u8(t.rx_buf ? 1 : 0);
        if (t.tx_buf)
            w.bytes(reinterpret_cast<const void*>(static_cast<uintptr_t>(t.tx_buf)), t.len);
    }
    if (!w.ok())
        return -EMSGSIZE;
    Reader r({});
    int result = roundtrip(w.size(), Op::SpiMessage, r);
    if (result < 0)
        return result;
    for (size_t i = 0; i < n; ++i) {
        const spi_ioc_transfer& t = xfers[i];
        if (!t.rx_buf)
            continue;
        auto b = r.bytes(t.len);
        if (!r.ok())
            return -EPROTO;
        std::memcpy(reinterpret_cast<void*>(static_cast<uintptr_t>(t.rx_buf)), b.data(), b.size());
    }
    return result;
}

int SimDeviceIo::small_ioctl(int fd, unsigned long request, void* arg) {
    const simproto::IoctlArg kind = simproto::classify_ioctl(request);
    uint64_t value = 0;
    if (kind.kind == simproto::ArgKind::Value)
        value = reinterpret_cast<uintptr_t>(arg);
    else if (kind.kind == simproto::ArgKind::PtrIn || kind.kind == simproto::ArgKind::PtrOut) {
        if (!arg || kind.size > sizeof value)
            return -EFAULT;
        if (kind.kind == simproto::ArgKind::PtrIn)
            std::memcpy(&value, arg, kind.size); // little-endian host, as the wire
    }
    Writer w(tx_);
    w.header(Op::Ioctl, ++seq_);
    w.i32(fd);
    w.u64(request);
    w.u64(value);
    Reader r({});
    int result = roundtrip(w.size(), Op::Ioctl, r);
    if (result < 0)
        return result;
    uint64_t out = r.u64();
    if (!r.ok())
        return -EPROTO;
    if (kind.kind == simproto::ArgKind::PtrOut)
        std::memcpy(arg, &out, kind.size);
    return result;
}

} // namespace caracara
