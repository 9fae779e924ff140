#include "drivers/platform/sim/sim_device_io.hpp"

#include <cerrno>
#include <cstring>
#include <linux/i2c-dev.h>
#include <linux/i2c.h>
#include <linux/spi/spidev.h>
#include <sys/ioctl.h>

namespace caracara {

using simproto::Op;
using simproto::Reader;
using simproto::Writer;

int SimDeviceIo::open(const char* path, int flags) {
    if (link_.reconnect_if_gone() < 0)
        return -ENODEV;
    Writer w = link_.request(Op::Open);
    w.str(path);
    w.i32(flags);
    if (!w.ok())
        return -ENAMETOOLONG;
    Reader r({});
    return link_.tagged(link_.roundtrip(w.size(), Op::Open, r));
}

int SimDeviceIo::close(int fd) {
    const int h = link_.wire_handle(fd);
    if (h < 0)
        return -ENODEV; // made on a connection that is gone
    Writer w = link_.request(Op::Close);
    w.i32(h);
    Reader r({});
    return link_.roundtrip(w.size(), Op::Close, r);
}

int SimDeviceIo::write(int fd, const void* buf, size_t len) {
    const int h = link_.wire_handle(fd);
    if (h < 0)
        return -ENODEV; // made on a connection that is gone
    Writer w = link_.request(Op::Write);
    w.i32(h);
    w.u32(static_cast<uint32_t>(len));
    w.bytes(buf, len);
    if (!w.ok())
        return -EMSGSIZE;
    Reader r({});
    return link_.roundtrip(w.size(), Op::Write, r);
}

int SimDeviceIo::gpio_request(const std::string& chip, const std::string& name, int offset, simproto::GpioMode mode,
                              bool active_low, int initial) {
    if (link_.reconnect_if_gone() < 0)
        return -ENODEV;
    Writer w = link_.request(Op::GpioRequest);
    w.str(chip);
    w.str(name);
    w.i32(offset);
    w.u8(static_cast<uint8_t>(mode));
    w.u8(active_low ? 1 : 0);
    w.u8(initial ? 1 : 0);
    if (!w.ok())
        return -ENAMETOOLONG;
    Reader r({});
    return link_.tagged(link_.roundtrip(w.size(), Op::GpioRequest, r));
}

int SimDeviceIo::simple(Op op, int32_t a, int32_t b) {
    const int h = link_.wire_handle(a);
    if (h < 0)
        return -ENODEV;
    Writer w = link_.request(op);
    w.i32(h);
    if (op == Op::GpioSet)
        w.u8(b ? 1 : 0);
    Reader r({});
    return link_.roundtrip(w.size(), op, r);
}

int SimDeviceIo::gpio_get(int line) { return simple(Op::GpioGet, line); }
int SimDeviceIo::gpio_set(int line, int value) { return simple(Op::GpioSet, line, value); }
int SimDeviceIo::gpio_release(int line) { return simple(Op::GpioRelease, line); }

int SimDeviceIo::ioctl(int fd, unsigned long request, void* arg) {
    fd = link_.wire_handle(fd);
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
    Writer w = link_.request(Op::I2cRdwr);
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
    int result = link_.roundtrip(w.size(), Op::I2cRdwr, r);
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
    Writer w = link_.request(Op::SpiMessage);
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
    int result = link_.roundtrip(w.size(), Op::SpiMessage, r);
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
    Writer w = link_.request(Op::Ioctl);
    w.i32(fd);
    w.u64(request);
    w.u64(value);
    Reader r({});
    int result = link_.roundtrip(w.size(), Op::Ioctl, r);
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
