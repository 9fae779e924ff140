#include "device_io.hpp"
#include "errors.hpp"
#include "sim_device_io.hpp"

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

int LinuxDeviceIo::close(int fd) {
    return ::close(fd) < 0 ? -errno : 0;
}

std::unique_ptr<DeviceIo> make_device_io(const std::string& spec, std::string& error) {
    if (spec == "linux")
        return std::make_unique<LinuxDeviceIo>();
    if (spec.rfind("sim:", 0) == 0 && spec.size() > 4) {
        auto io = std::make_unique<SimDeviceIo>();
        int r = io->connect(spec.substr(4));
        if (r < 0) {
            error = "cannot connect to caracara-sim at " + spec.substr(4) + ": " + errno_name(-r);
            return nullptr;
        }
        return io;
    }
    error = "hardware must be 'linux' or 'sim:SOCKET', got '" + spec + "'";
    return nullptr;
}

} // namespace caracara
