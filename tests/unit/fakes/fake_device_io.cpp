#include "tests/unit/fakes/fake_device_io.hpp"

#include "drivers/protocol/seabotix.hpp"

#include <algorithm>
#include <cerrno>
#include <linux/i2c-dev.h>
#include <linux/i2c.h>

namespace caracara::test {

int FakeDeviceIo::open(const char* path, int) {
    return config_.i2c.device == path ? kAdapterFd : -ENOENT;
}

int FakeDeviceIo::ioctl(int fd, unsigned long request, void* arg) {
    if (fd != kAdapterFd)
        return -EBADF;
    switch (request) {
    case I2C_FUNCS: *static_cast<unsigned long*>(arg) = I2C_FUNC_I2C; return 0;
    case I2C_TIMEOUT:
    case I2C_RETRIES: return 0;
    case I2C_RDWR: return transfer(arg);
    }
    return -ENOTTY;
}

int FakeDeviceIo::transfer(void* arg) {
    const auto* data = static_cast<const i2c_rdwr_ioctl_data*>(arg);
    for (__u32 n = 0; n < data->nmsgs; ++n) {
        i2c_msg& m = data->msgs[n];
        const auto& ts = config_.thrusters;
        const auto it = std::find_if(ts.begin(), ts.end(), [&](const ThrusterConfig& t) { return mt_addr7(t.mt) == m.addr; });
        if (it == ts.end()) {
            if (is_valid_mux_addr7(m.addr))
                continue; // a mux select
            return -ENXIO;
        }
        const std::size_t i = static_cast<std::size_t>(it - ts.begin());
        wire_.wait_released();
        if (wire_.locked())
            return -ETIMEDOUT;
        if (int err = wire_.failure(i))
            return -err;
        if (m.flags & I2C_M_RD) {
            const auto reply = encode_seabotix_status(it->mt, 0, wire_.faults(i), 0, kSpeedStop, 20);
            std::copy_n(reply.begin(), std::min<std::size_t>(m.len, reply.size()), m.buf);
            wire_.add({WireEvent::Kind::StatusRead, i, 0, 0});
            continue;
        }
        const DecodedOrder d = decode_order(it->mt, {m.buf, m.len});
        if (d.error != CodecError::None)
            return -EIO;
        const int32_t value = speed_to_motor(d.speed).value_or(0);
        wire_.add({WireEvent::Kind::Order, i, it->reversed ? -value : value, d.speed});
    }
    return static_cast<int>(data->nmsgs);
}

} // namespace caracara::test
