#include "drivers/platform/i2c_dev.hpp"

#include <cerrno>
#include <fcntl.h>
#include <linux/i2c-dev.h>

namespace caracara {

int I2cDev::open() {
    close();
    int fd = io_.open(path_.c_str(), O_RDWR);
    if (fd < 0)
        return fd;
    unsigned long funcs = 0;
    int r = io_.ioctl(fd, I2C_FUNCS, &funcs);
    if (r < 0 || !(funcs & I2C_FUNC_I2C)) {
        io_.close(fd);
        return r < 0 ? r : -EOPNOTSUPP;
    }
    // Value ioctls: the argument is the value itself. I2C_TIMEOUT counts in units of 10 ms.
    if (limits_.timeout_ms && (r = io_.ioctl(fd, I2C_TIMEOUT, reinterpret_cast<void*>(
                                                                    static_cast<uintptr_t>((*limits_.timeout_ms + 9) / 10)))) < 0) {
        io_.close(fd);
        return r;
    }
    if (limits_.retries &&
        (r = io_.ioctl(fd, I2C_RETRIES, reinterpret_cast<void*>(static_cast<uintptr_t>(*limits_.retries)))) < 0) {
        io_.close(fd);
        return r;
    }
    fd_ = fd;
    return 0;
}

void I2cDev::close() {
    if (fd_ >= 0) {
        io_.close(fd_);
        fd_ = -1;
    }
}

IoError I2cDev::transfer(std::span<i2c_msg> msgs) {
    if (fd_ < 0) {
        last_errno_ = ENODEV;
        return IoError::NoDevice;
    }
    i2c_rdwr_ioctl_data data{msgs.data(), static_cast<__u32>(msgs.size())};
    int r = io_.ioctl(fd_, I2C_RDWR, &data);
    if (r < 0) {
        last_errno_ = -r;
        return io_error_from_errno(-r);
    }
    // The kernel returns the number of messages transferred; fewer means the rest never ran.
    if (static_cast<size_t>(r) != msgs.size()) {
        last_errno_ = EIO;
        return IoError::ClockStretch;
    }
    return IoError::None;
}

IoError I2cDev::write(uint16_t addr7, std::span<const uint8_t> data) {
    i2c_msg m{addr7, 0, static_cast<__u16>(data.size()), const_cast<__u8*>(data.data())};
    return transfer({&m, 1});
}

IoError I2cDev::read(uint16_t addr7, std::span<uint8_t> data) {
    i2c_msg m{addr7, I2C_M_RD, static_cast<__u16>(data.size()), data.data()};
    return transfer({&m, 1});
}

} // namespace caracara
