#include "drivers/platform/linux/linux_device_io.hpp"

#include <cerrno>
#include <fcntl.h>
#include <sys/ioctl.h>
#include <unistd.h>

namespace caracara {

int LinuxDeviceIo::open(const char* path, int flags) {
    int fd = ::open(path, flags | O_CLOEXEC);
    return fd < 0 ? -errno : fd;
}

int LinuxDeviceIo::ioctl(int fd, unsigned long request, void* arg) {
    int r;
    do {
        r = ::ioctl(fd, request, arg);
    } while (r < 0 && errno == EINTR);
    return r < 0 ? -errno : r;
}

int LinuxDeviceIo::write(int fd, const void* buf, size_t len) {
    ssize_t n;
    do {
        n = ::write(fd, buf, len);
    } while (n < 0 && errno == EINTR);
    return n < 0 ? -errno : static_cast<int>(n);
}

int LinuxDeviceIo::close(int fd) {
    return ::close(fd) < 0 ? -errno : 0;
}

} // namespace caracara
