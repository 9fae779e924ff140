#include "sim/kernel_bridge.hpp"

#include "core/clock.hpp"
#include "sim/kernel_bridge_abi.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fcntl.h>
#include <linux/i2c.h>
#include <linux/spi/spi.h>
#include <unistd.h>

namespace caracara::sim {

namespace {

// Reads fixed-size structures and byte runs from a request payload.
class Cursor {
public:
    explicit Cursor(std::span<const uint8_t> d) : d_(d) {}
    template <typename T> bool get(T& out) {
        if (d_.size() - pos_ < sizeof(T))
            return ok_ = false;
        std::memcpy(&out, d_.data() + pos_, sizeof(T));
        pos_ += sizeof(T);
        return true;
    }
    std::span<const uint8_t> bytes(size_t n) {
        if (d_.size() - pos_ < n) {
            ok_ = false;
            return {};
        }
        auto s = d_.subspan(pos_, n);
        pos_ += n;
        return s;
    }
    bool ok() const { return ok_; }
    bool at_end() const { return pos_ == d_.size(); }

private:
    std::span<const uint8_t> d_;
    size_t pos_ = 0;
    bool ok_ = true;
};

void sleep_until(uint64_t deadline_ns) {
    timespec ts{static_cast<time_t>(deadline_ns / 1'000'000'000ull), static_cast<long>(deadline_ns % 1'000'000'000ull)};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    }
}

} // namespace

KernelBridge::KernelBridge(sd_event* event, SimVehicle& vehicle, const SimConfig& cfg)
    : event_(event), vehicle_(vehicle), cfg_(cfg) {
    buf_.resize(CCB_MAX_MESSAGE);
}

KernelBridge::~KernelBridge() {
    if (hooked_)
        vehicle_.gpio().on_change = previous_on_change_;
    io_.reset();
    if (fd_ >= 0)
        ::close(fd_);
}

int KernelBridge::open(const std::string& device) {
    int fd = ::open(device.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return -errno;
    fd_ = fd;
    sd_event_source* s = nullptr;
    if (int r = sd_event_add_io(event_, &s, fd, EPOLLIN, on_io, this); r < 0)
        return r;
    io_.reset(s);
    // Every level change of the model's lines goes to the kernel, which fires edge interrupts
    // from it; whoever else watches the model (the device server) is still told.
    auto& gpio = vehicle_.gpio();
    previous_on_change_ = gpio.on_change;
    hooked_ = true;
    gpio.on_change = [this](int line, int value, uint64_t when_ns) {
        if (previous_on_change_)
            previous_on_change_(line, value, when_ns);
        const uint32_t offset = vehicle_.gpio().lines()[static_cast<size_t>(line)].offset;
        push_level(offset, vehicle_.gpio().level(offset)); // physical, whatever the model's active-low
    };
    // The kernel starts with every line low: tell it the levels as they are now.
    for (const auto& l : gpio.lines())
        push_level(l.offset, gpio.level(l.offset));
    return 0;
}

void KernelBridge::push_level(uint32_t offset, int level) {
    if (fd_ < 0)
        return;
    ccb_gpio g{offset, static_cast<uint32_t>(level ? 1 : 0), 0};
    send(CCB_GPIO_LEVEL, 0, 0, 0, {reinterpret_cast<const uint8_t*>(&g), sizeof g});
}

void KernelBridge::send(uint16_t type, uint32_t seq, uint16_t arg, int32_t result, std::span<const uint8_t> payload) {
    std::vector<uint8_t> msg(sizeof(ccb_header) + payload.size());
    ccb_header h{static_cast<uint32_t>(msg.size()), seq, type, arg, result};
    std::memcpy(msg.data(), &h, sizeof h);
    if (!payload.empty())
        std::memcpy(msg.data() + sizeof h, payload.data(), payload.size());
    ssize_t n;
    do {
        n = ::write(fd_, msg.data(), msg.size());
    } while (n < 0 && errno == EINTR);
    if (n < 0)
        std::fprintf(stderr, "caracara-sim: kernel bridge: write (type 0x%x seq %u): %s\n", type, seq,
                     std::strerror(errno));
}

int KernelBridge::on_io(sd_event_source*, int fd, uint32_t, void* userdata) {
    auto* self = static_cast<KernelBridge*>(userdata);
    for (;;) {
        ssize_t n = ::read(fd, self->buf_.data(), self->buf_.size());
        if (n < 0) {
            if (errno != EAGAIN && errno != EINTR)
                std::fprintf(stderr, "caracara-sim: kernel bridge: read: %s\n", std::strerror(errno));
            return 0;
        }
        self->handle({self->buf_.data(), static_cast<size_t>(n)});
    }
}

void KernelBridge::handle(std::span<const uint8_t> req) {
    ++requests_;
    ccb_header h{};
    if (req.size() < sizeof h) {
        ++bad_requests_;
        return;
    }
    std::memcpy(&h, req.data(), sizeof h);
    auto payload = req.subspan(sizeof h);
    payload_.clear();
    int32_t result = 0;
    switch (h.type) {
    case CCB_I2C_XFER: handle_i2c(payload, result); break;
    case CCB_SPI_MSG: handle_spi(payload, result); break;
    case CCB_GPIO: result = handle_gpio(h.arg, payload); break;
    case CCB_I2C_BIND: {
        // The adapter's platform driver was bound or unbound through sysfs: the same event
        // the device socket's sysfs writes are (pins back to I2C, bind/unbind counters).
        const auto kind = h.arg ? SimVehicle::NodeKind::Bind : SimVehicle::NodeKind::Unbind;
        int r = vehicle_.sysfs_write(kind, cfg_.driver_id, monotonic_ns());
        if (r < 0)
            std::fprintf(stderr, "caracara-sim: kernel bridge: driver %s of %s: the model says %s\n",
                         h.arg ? "bound" : "unbound", cfg_.driver_id.c_str(), std::strerror(-r));
        break;
    }
    default:
        ++bad_requests_;
        result = -EBADMSG;
    }
    send(static_cast<uint16_t>(h.type | CCB_REPLY), h.seq, h.arg, result, payload_);
}

void KernelBridge::handle_i2c(std::span<const uint8_t> payload, int32_t& result) {
    Cursor c(payload);
    uint32_t count = 0;
    c.get(count);
    std::vector<I2cMessage> msgs(count);
    for (auto& m : msgs) {
        ccb_i2c_msg km{};
        if (!c.get(km))
            break;
        m.addr = km.addr;
        m.flags = km.flags;
        if (m.flags & I2C_M_RD) {
            m.data.assign(km.len, 0);
        } else {
            auto b = c.bytes(km.len);
            m.data.assign(b.begin(), b.end());
        }
    }
    if (!c.ok() || !c.at_end() || count == 0) {
        ++bad_requests_;
        result = -EBADMSG;
        return;
    }
    const uint64_t start = vehicle_.wire_start(monotonic_ns());
    auto res = vehicle_.i2c().transfer(msgs, start);
    if (vehicle_.realistic_timing()) {
        vehicle_.bus_free_at() = start + res.wire_ns;
        sleep_until(vehicle_.bus_free_at());
    }
    result = res.ret;
    if (res.ret >= 0)
        for (auto& m : msgs)
            if (m.flags & I2C_M_RD)
                payload_.insert(payload_.end(), m.data.begin(), m.data.end());
}

void KernelBridge::handle_spi(std::span<const uint8_t> payload, int32_t& result) {
    Cursor c(payload);
    ccb_spi_msg km{};
    c.get(km);
    std::vector<SpiMessageXfer> xfers(km.count);
    for (auto& x : xfers) {
        ccb_spi_xfer kx{};
        if (!c.get(kx))
            break;
        x.len = kx.len;
        x.params.speed_hz = kx.speed_hz;
        x.params.delay_usecs = kx.delay_usecs;
        x.params.bits_per_word = kx.bits_per_word;
        x.params.cs_change = kx.cs_change != 0;
        x.want_rx = kx.want_rx != 0;
        if (kx.has_tx) {
            auto b = c.bytes(kx.len);
            x.tx.assign(b.begin(), b.end());
        }
    }
    if (!c.ok() || !c.at_end()) {
        ++bad_requests_;
        result = -EBADMSG;
        return;
    }
    // The one chip select this controller has is the Teensy's spidev node of the config.
    SpiPort& port = vehicle_.teensy_port();
    port.mode = static_cast<uint8_t>(km.mode & (SPI_CPHA | SPI_CPOL));
    port.lsb_first = (km.mode & SPI_LSB_FIRST) ? 1 : 0;
    port.bits_per_word = km.bits_per_word ? km.bits_per_word : 8;
    if (km.max_speed_hz)
        port.max_speed_hz = km.max_speed_hz;
    const uint64_t start = vehicle_.spi_wire_start(monotonic_ns());
    uint64_t wire = 0;
    result = vehicle_.spi_message(port, xfers, start, wire);
    if (vehicle_.realistic_timing()) {
        vehicle_.spi_free_at() = start + wire;
        sleep_until(vehicle_.spi_free_at());
    }
    for (auto& x : xfers)
        if (x.want_rx)
            payload_.insert(payload_.end(), x.rx.begin(), x.rx.end());
}

int32_t KernelBridge::handle_gpio(uint16_t op, std::span<const uint8_t> payload) {
    Cursor c(payload);
    ccb_gpio g{};
    if (!c.get(g) || !c.at_end()) {
        ++bad_requests_;
        return -EBADMSG;
    }
    GpioModel& gpio = vehicle_.gpio();
    const int line = gpio.find(GpioModel::kChip, "", static_cast<int>(g.offset));
    if (line < 0)
        return -ENODEV; // a line of the chip that the vehicle does not wire
    const uint64_t now = monotonic_ns();
    auto it = modes_.find(line);
    // The model takes a line with its mode; the kernel sets direction after the request, and
    // again whenever it changes it. Levels here are physical: the kernel did any inversion.
    auto configure = [&](GpioMode mode, int value) -> int32_t {
        if (it != modes_.end()) {
            if (it->second == mode)
                return mode == GpioMode::Input ? 0 : gpio.set(line, value, now);
            gpio.release(line, now);
            modes_.erase(it);
        }
        if (int r = gpio.request(line, mode, false, value, now); r < 0)
            return r;
        modes_[line] = mode;
        return 0;
    };
    switch (op) {
    case CCB_GPIO_REQUEST:
        return it == modes_.end() && gpio.requested(line) ? -EBUSY : 0;
    case CCB_GPIO_FREE:
        if (it != modes_.end()) {
            gpio.release(line, now);
            modes_.erase(it);
        }
        return 0;
    case CCB_GPIO_INPUT: return configure(GpioMode::Input, 0);
    case CCB_GPIO_OUTPUT:
        return configure((g.flags & CCB_GPIO_OPEN_DRAIN) ? GpioMode::OpenDrain : GpioMode::Output, g.value ? 1 : 0);
    case CCB_GPIO_SET:
        if (it == modes_.end())
            return -EINVAL;
        return gpio.set(line, g.value ? 1 : 0, now);
    case CCB_GPIO_GET: return it != modes_.end() ? gpio.get(line) : (gpio.level(g.offset) ? 1 : 0);
    default: ++bad_requests_; return -EBADMSG;
    }
}

} // namespace caracara::sim
