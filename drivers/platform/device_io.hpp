// The hardware seam. Everything above this interface is the code that runs on the SBC;
// below it is either the kernel (LinuxDeviceIo) or caracara-sim (SimDeviceIo), which
// receives the very i2c_msg / spi_ioc_transfer arrays the driver built.
#pragma once

#include <cstddef>
#include <memory>

namespace caracara {

class DeviceIo {
public:
    virtual ~DeviceIo() = default;
    // Each returns >= 0 on success or -errno, never touching the global errno contract.
    virtual int open(const char* path, int flags) = 0;
    // `arg` is what the kernel's ioctl(2) would receive: a pointer for pointer ioctls,
    // the value cast to a pointer for value ioctls (I2C_TIMEOUT, I2C_RETRIES).
    virtual int ioctl(int fd, unsigned long request, void* arg) = 0;
    virtual int close(int fd) = 0;
    // For sysfs attribute files (driver bind/unbind during bus recovery). Bytes written or -errno.
    virtual int write(int fd, const void* buf, size_t len) = 0;
};

} // namespace caracara
