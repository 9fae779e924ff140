#include "sim/device_ops.hpp"

#include <cerrno>
#include <linux/i2c-dev.h>
#include <linux/i2c.h>
#include <linux/spi/spidev.h>
#include <string>
#include <vector>

namespace caracara::sim {

using simproto::Op;

namespace {
// What an i2c-dev adapter like i2c-bcm2835 advertises.
constexpr unsigned long kI2cFuncs = I2C_FUNC_I2C | I2C_FUNC_SMBUS_EMUL;
} // namespace

// One request being served: what it says, and its reply being written.
struct DeviceOps::Request {
    DeviceOps& ops;
    DeviceSession& session;
    simproto::Reader r;
    simproto::Writer w;
    simproto::Header h;
    Op op;
    std::span<uint8_t> reply;

    void begin(int result) {
        w.header(op, h.seq, true);
        w.i32(result);
    }
    uint64_t bad(int err) {
        ++ops.bad_requests_;
        w = simproto::Writer(reply);
        begin(err);
        return 0;
    }
    // The open device handle `hnd` for a transfer on a `kind` node: nullptr with `err` set as the
    // kernel would answer (EBADF: not open; ENOTTY: the wrong kind of device for the ioctl).
    const DeviceSession::Handle* device(int32_t hnd, SimVehicle::NodeKind kind, int& err) {
        auto it = session.handles.find(hnd);
        err = it == session.handles.end() ? -EBADF : it->second.kind != kind ? -ENOTTY : 0;
        if (!err && it->second.epoch != ops.vehicle_.node_epoch(kind))
            err = -ENODEV; // the device vanished after this handle was opened
        return err ? nullptr : &it->second;
    }
};

const DeviceOps::Entry DeviceOps::kTable[] = {
    {Op::Open, &DeviceOps::open},
    {Op::Close, &DeviceOps::close},
    {Op::I2cRdwr, &DeviceOps::i2c_rdwr},
    {Op::SpiMessage, &DeviceOps::spi_message},
    {Op::Ioctl, &DeviceOps::ioctl},
    {Op::Write, &DeviceOps::write},
    {Op::GpioRequest, &DeviceOps::gpio_request},
    {Op::GpioGet, &DeviceOps::gpio_line_op},
    {Op::GpioSet, &DeviceOps::gpio_line_op},
    {Op::GpioRelease, &DeviceOps::gpio_line_op},
    {Op::GpioWatch, &DeviceOps::gpio_watch},
};

size_t DeviceOps::handle(DeviceSession& session, std::span<const uint8_t> req, std::span<uint8_t> reply,
                         uint64_t& wire_ns, bool truncated) {
    Request q{*this, session, simproto::Reader(req), simproto::Writer(reply), {}, Op::Open, reply};
    wire_ns = 0;
    held_ns_ = 0;
    on_spi_ = false;
    if (!q.r.header(q.h) || (q.h.op & simproto::kReplyBit)) {
        // Not even a header we understand: answer with a bare error so the client is not left hanging.
        q.op = static_cast<Op>(q.h.op & ~simproto::kReplyBit);
        q.bad(-EBADMSG);
        return q.w.size();
    }
    q.op = static_cast<Op>(q.h.op);
    if (truncated) {
        q.bad(-EMSGSIZE);
        return q.w.size();
    }
    Handler handler = nullptr;
    for (const Entry& e : kTable)
        if (e.op == q.op)
            handler = e.handler;
    if (!handler) {
        q.bad(-EBADMSG); // unknown op, or GpioEvent (sent by the simulator only)
        return q.w.size();
    }
    wire_ns = (this->*handler)(q);
    if (!q.w.ok()) {
        // A reply longer than the protocol allows is an error, never a silent truncation.
        q.bad(-EMSGSIZE);
        wire_ns = 0;
    }
    return q.w.size();
}

void DeviceOps::release(DeviceSession& session) {
    for (auto& [h, line] : session.gpio_lines)
        if (session.gpio_epochs[h] == vehicle_.gpio().epoch(line)) // not one gone since
            vehicle_.gpio().release(line, monotonic_ns());
    session.gpio_lines.clear();
    session.gpio_epochs.clear();
}

uint64_t DeviceOps::open(Request& q) {
    auto path = q.r.str(4096);
    q.r.i32(); // flags: the simulated nodes ignore O_* like a char device mostly does
    if (!q.r.ok() || !q.r.at_end())
        return q.bad(-EBADMSG);
    auto kind = vehicle_.node_kind(std::string(path), monotonic_ns());
    if (kind == SimVehicle::NodeKind::None)
        return q.bad(-ENOENT);
    int hnd = q.session.next_handle++;
    q.session.handles[hnd] = {kind, std::string(path), vehicle_.node_epoch(kind)};
    q.begin(hnd);
    return 0;
}

uint64_t DeviceOps::close(Request& q) {
    int32_t hnd = q.r.i32();
    if (!q.r.ok() || !q.r.at_end())
        return q.bad(-EBADMSG);
    if (!q.session.handles.erase(hnd))
        return q.bad(-EBADF);
    q.begin(0);
    return 0;
}

uint64_t DeviceOps::i2c_rdwr(Request& q) {
    int32_t hnd = q.r.i32();
    uint32_t n = q.r.u32();
    if (!q.r.ok())
        return q.bad(-EBADMSG);
    int err = 0;
    if (!q.device(hnd, SimVehicle::NodeKind::I2c, err))
        return q.bad(err);
    if (n == 0 || n > I2C_RDWR_IOCTL_MAX_MSGS)
        return q.bad(-EINVAL);
    if (!vehicle_.i2c_present(monotonic_ns()))
        return q.bad(-ENODEV); // the adapter was unbound under an open file
    std::vector<I2cMessage> msgs(n);
    for (auto& m : msgs) {
        m.addr = q.r.u16();
        m.flags = q.r.u16();
        uint16_t len = q.r.u16();
        if (!q.r.ok() || len > 8192)
            return q.bad(-EBADMSG);
        if (m.flags & I2C_M_RD)
            m.data.assign(len, 0);
        else {
            auto b = q.r.bytes(len);
            m.data.assign(b.begin(), b.end());
        }
    }
    if (!q.r.ok() || !q.r.at_end())
        return q.bad(-EBADMSG);
    const uint64_t start = vehicle_.wire_start(monotonic_ns());
    auto res = vehicle_.i2c().transfer(msgs, start);
    held_ns_ = res.held_ns;
    q.begin(res.ret);
    if (res.ret >= 0)
        for (auto& m : msgs)
            if (m.flags & I2C_M_RD)
                q.w.bytes(m.data.data(), m.data.size());
    return res.wire_ns;
}

uint64_t DeviceOps::spi_message(Request& q) {
    int32_t hnd = q.r.i32();
    uint32_t n = q.r.u32();
    if (!q.r.ok())
        return q.bad(-EBADMSG);
    int err = 0;
    const DeviceSession::Handle* dev = q.device(hnd, SimVehicle::NodeKind::Spi, err);
    if (!dev)
        return q.bad(err);
    if (n > 512)
        return q.bad(-EINVAL);
    std::vector<SpiMessageXfer> xfers(n);
    size_t total = 0;
    for (auto& x : xfers) {
        x.len = q.r.u32();
        x.params.speed_hz = q.r.u32();
        x.params.delay_usecs = q.r.u16();
        x.params.bits_per_word = q.r.u8();
        x.params.cs_change = q.r.u8() != 0;
        const bool has_tx = q.r.u8() != 0;
        x.want_rx = q.r.u8() != 0;
        total += x.len;
        if (!q.r.ok() || total > 8192)
            return q.bad(-EBADMSG);
        if (has_tx) {
            auto b = q.r.bytes(x.len);
            x.tx.assign(b.begin(), b.end());
        }
    }
    if (!q.r.ok() || !q.r.at_end())
        return q.bad(-EBADMSG);
    SpiPort* port = vehicle_.spi_port(dev->path);
    const uint64_t start = vehicle_.spi_wire_start(monotonic_ns());
    uint64_t wire = 0;
    int res = vehicle_.spi_message(*port, xfers, start, wire);
    on_spi_ = true;
    // A hung Teensy: the message is answered only after the hang (the daemon's SPI worker waits).
    held_ns_ = uint64_t{port->hang_ms} * 1'000'000ull;
    wire += held_ns_;
    q.begin(res);
    for (auto& x : xfers)
        if (x.want_rx)
            q.w.bytes(x.rx.data(), x.rx.size());
    return wire;
}

uint64_t DeviceOps::ioctl(Request& q) {
    int32_t hnd = q.r.i32();
    uint64_t request = q.r.u64();
    uint64_t value = q.r.u64();
    if (!q.r.ok() || !q.r.at_end())
        return q.bad(-EBADMSG);
    auto it = q.session.handles.find(hnd);
    if (it == q.session.handles.end())
        return q.bad(-EBADF);
    uint64_t out = 0;
    int result = 0;
    if (it->second.kind == SimVehicle::NodeKind::Unbind || it->second.kind == SimVehicle::NodeKind::Bind) {
        result = -ENOTTY;
    } else if (it->second.kind == SimVehicle::NodeKind::I2c) {
        switch (request) {
        case I2C_FUNCS: out = kI2cFuncs; break;
        case I2C_TIMEOUT:
            // Units of 10 ms, as i2c-dev takes it.
            vehicle_.i2c_timeout = static_cast<int64_t>(value);
            vehicle_.i2c().set_timeout_ns(value * 10'000'000ull);
            break;
        case I2C_RETRIES: vehicle_.i2c_retries = static_cast<int64_t>(value); break;
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
        return q.bad(result);
    q.begin(result);
    q.w.u64(out);
    return 0;
}

uint64_t DeviceOps::write(Request& q) {
    int32_t hnd = q.r.i32();
    uint32_t n = q.r.u32();
    auto data = q.r.bytes(n);
    if (!q.r.ok() || !q.r.at_end())
        return q.bad(-EBADMSG);
    auto it = q.session.handles.find(hnd);
    if (it == q.session.handles.end())
        return q.bad(-EBADF);
    if (it->second.kind != SimVehicle::NodeKind::Unbind && it->second.kind != SimVehicle::NodeKind::Bind)
        return q.bad(-EINVAL);
    int res = vehicle_.sysfs_write(it->second.kind,
                                   {reinterpret_cast<const char*>(data.data()), data.size()}, monotonic_ns());
    q.begin(res);
    return 0;
}

uint64_t DeviceOps::gpio_request(Request& q) {
    auto chip = std::string(q.r.str(256));
    auto name = std::string(q.r.str(256));
    int32_t offset = q.r.i32();
    uint8_t mode = q.r.u8();
    uint8_t active_low = q.r.u8();
    uint8_t initial = q.r.u8();
    if (!q.r.ok() || !q.r.at_end() || mode > static_cast<uint8_t>(GpioMode::OpenDrain))
        return q.bad(-EBADMSG);
    int line = vehicle_.gpio().find(chip, name, offset);
    if (line < 0)
        return q.bad(line);
    int res = vehicle_.gpio().request(line, static_cast<GpioMode>(mode), active_low, initial, monotonic_ns());
    if (res < 0)
        return q.bad(res);
    int hnd = q.session.next_handle++;
    q.session.gpio_lines[hnd] = line;
    q.session.gpio_epochs[hnd] = vehicle_.gpio().epoch(line);
    q.begin(hnd);
    return 0;
}

uint64_t DeviceOps::gpio_line_op(Request& q) {
    int32_t hnd = q.r.i32();
    uint8_t value = q.op == Op::GpioSet ? q.r.u8() : 0;
    if (!q.r.ok() || !q.r.at_end())
        return q.bad(-EBADMSG);
    auto it = q.session.gpio_lines.find(hnd);
    if (it == q.session.gpio_lines.end())
        return q.bad(-EBADF);
    int res = 0;
    // A handle to a line that went away since: dead for good, as a file descriptor of a removed
    // chip is (its release frees nothing: the line may be another handle's by now).
    const bool stale = q.session.gpio_epochs[hnd] != vehicle_.gpio().epoch(it->second);
    if (stale && q.op != Op::GpioRelease)
        res = -ENODEV;
    else if (q.op == Op::GpioGet)
        res = vehicle_.gpio().get(it->second);
    else if (q.op == Op::GpioSet)
        res = vehicle_.gpio().set(it->second, value, monotonic_ns());
    else {
        if (!stale)
            vehicle_.gpio().release(it->second, monotonic_ns());
        q.session.gpio_lines.erase(it);
        q.session.gpio_epochs.erase(hnd);
    }
    q.begin(res);
    return 0;
}

uint64_t DeviceOps::gpio_watch(Request& q) {
    auto chip = std::string(q.r.str(256));
    auto name = std::string(q.r.str(256));
    int32_t offset = q.r.i32();
    if (!q.r.ok() || !q.r.at_end())
        return q.bad(-EBADMSG);
    int line = vehicle_.gpio().find(chip, name, offset);
    if (line < 0)
        return q.bad(line);
    if (!vehicle_.gpio().present(line))
        return q.bad(-ENODEV);
    q.session.watched_line = line;
    q.begin(0);
    return 0;
}

} // namespace caracara::sim
