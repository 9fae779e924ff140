// The real system calls behind the seam: /dev/i2c-N, /dev/spidevB.C, sysfs attributes.
#pragma once

#include "drivers/platform/device_io.hpp"

namespace caracara {

class LinuxDeviceIo final : public DeviceIo {
public:
    int open(const char* path, int flags) override;
    int ioctl(int fd, unsigned long request, void* arg) override;
    int close(int fd) override;
    int write(int fd, const void* buf, size_t len) override;
};

} // namespace caracara
