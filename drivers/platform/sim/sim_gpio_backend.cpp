// GpioBackend for caracara-sim: line operations travel on the SimDeviceIo connection; each
// input with edge events gets a socket of its own on which the simulator pushes the edges,
// so the daemon's sd-event loop watches it exactly like a libgpiod event fd.
#include "drivers/platform/sim/sim_gpio_backend.hpp"

#include <cerrno>
#include <cstring>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

namespace caracara {

namespace {

// The API's modes and the device protocol's are separate enums: the wire values are fixed by
// drivers/protocol/sim_protocol.hpp, the API may grow.
simproto::GpioMode wire_mode(GpioMode m) {
    switch (m) {
    case GpioMode::Input: return simproto::GpioMode::Input;
    case GpioMode::InputEdges: return simproto::GpioMode::InputEdges;
    case GpioMode::Output: return simproto::GpioMode::Output;
    case GpioMode::OpenDrain: return simproto::GpioMode::OpenDrain;
    }
    return simproto::GpioMode::Input;
}

int connect_watch(const std::string& socket_path, const GpioLineSpec& spec) {
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    if (socket_path.size() >= sizeof addr.sun_path)
        return -ENAMETOOLONG;
    std::memcpy(addr.sun_path, socket_path.c_str(), socket_path.size() + 1);
    int s = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
    if (s < 0)
        return -errno;
    if (::connect(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) {
        int e = errno;
        ::close(s);
        return -e;
    }
    uint8_t buf[512];
    simproto::Writer w(buf);
    w.header(simproto::Op::GpioWatch, 1);
    w.str(spec.chip);
    w.str(spec.offset ? std::string() : spec.name);
    w.i32(spec.offset ? static_cast<int32_t>(*spec.offset) : -1);
    uint8_t reply[64];
    ssize_t n = -1;
    if (w.ok() && ::send(s, buf, w.size(), MSG_NOSIGNAL) >= 0)
        n = ::recv(s, reply, sizeof reply, 0);
    simproto::Reader r({reply, n > 0 ? static_cast<size_t>(n) : 0});
    simproto::Header h;
    const int32_t result = (n > 0 && r.header(h)) ? r.i32() : -EPROTO;
    if (result < 0) {
        ::close(s);
        return result;
    }
    return s;
}

class SimGpioLine final : public GpioLine {
public:
    SimGpioLine(SimDeviceIo& io, int handle, int watch_fd) : io_(io), handle_(handle), watch_fd_(watch_fd) {}
    ~SimGpioLine() override {
        io_.gpio_release(handle_);
        if (watch_fd_ >= 0)
            ::close(watch_fd_);
    }
    int get() override { return io_.gpio_get(handle_); }
    int set(int value) override { return io_.gpio_set(handle_, value); }
    bool set_in_signal_handler(int value) noexcept override { return io_.gpio_set_in_signal_handler(handle_, value); }
    int event_fd() const override { return watch_fd_; }
    int drain_events() override {
        if (watch_fd_ < 0)
            return 0;
        int count = 0;
        uint8_t buf[64];
        for (;;) {
            ssize_t n = ::recv(watch_fd_, buf, sizeof buf, MSG_DONTWAIT);
            if (n > 0) {
                ++count;
                continue;
            }
            if (n == 0)
                return -ENODEV; // the simulator went away
            return (errno == EAGAIN || errno == EWOULDBLOCK) ? count : -errno;
        }
    }

private:
    SimDeviceIo& io_;
    int handle_;
    int watch_fd_;
};

class SimGpioBackend final : public GpioBackend {
public:
    explicit SimGpioBackend(SimDeviceIo& io) : io_(io) {}
    std::unique_ptr<GpioLine> request(const GpioLineSpec& spec, GpioMode mode, int initial, std::string& error) override {
        int h = io_.gpio_request(spec.chip, spec.offset ? std::string() : spec.name,
                                 spec.offset ? static_cast<int>(*spec.offset) : -1, wire_mode(mode), spec.active_low, initial);
        if (h < 0) {
            error = spec.describe() + ": " + errno_name(-h);
            return nullptr;
        }
        int watch = -1;
        if (mode == GpioMode::InputEdges) {
            watch = connect_watch(io_.socket_path(), spec);
            if (watch < 0) {
                io_.gpio_release(h);
                error = spec.describe() + ": cannot watch edges: " + errno_name(-watch);
                return nullptr;
            }
        }
        return std::make_unique<SimGpioLine>(io_, h, watch);
    }

private:
    SimDeviceIo& io_;
};

} // namespace

std::unique_ptr<GpioBackend> make_sim_gpio_backend(SimDeviceIo& io) { return std::make_unique<SimGpioBackend>(io); }

} // namespace caracara
