// DeviceIo that hands each open/ioctl/close to caracara-sim over its SimConnection (a Unix
// socket) and copies the replies and errno back exactly as the kernel would. No allocation per
// call. When the simulator goes away every call fails with ENODEV (the adapter is gone); the
// next open or line request connects again, so a restarted simulator is picked up by whoever
// reopens.
#pragma once

#include "drivers/platform/device_io.hpp"
#include "drivers/platform/sim/sim_connection.hpp"
#include "drivers/protocol/sim_protocol.hpp"

#include <cstdint>
#include <string>

namespace caracara {

class SimDeviceIo final : public DeviceIo {
public:
    int connect(const std::string& socket_path) { return link_.connect(socket_path); } // -errno on failure
    int open(const char* path, int flags) override;
    int ioctl(int fd, unsigned long request, void* arg) override;
    int close(int fd) override;
    int write(int fd, const void* buf, size_t len) override;

    // GPIO lines of the simulated vehicle (see GpioBackend); results as the ops above.
    int gpio_request(const std::string& chip, const std::string& name, int offset, simproto::GpioMode mode,
                     bool active_low, int initial);
    int gpio_get(int line);
    int gpio_set(int line, int value);
    int gpio_release(int line);
    // GpioSet from a fatal-signal handler: one send of a message built on the stack, then a
    // bounded wait (50 ms) for its reply, sequence number 0 (roundtrip() skips it if it gets it).
    bool gpio_set_in_signal_handler(int line, int value) noexcept { return link_.gpio_set_in_signal_handler(line, value); }
    const std::string& socket_path() const { return link_.socket_path(); }

private:
    int i2c_rdwr(int fd, void* arg);
    int spi_message(int fd, unsigned long request, void* arg);
    int small_ioctl(int fd, unsigned long request, void* arg);
    int simple(simproto::Op op, int32_t a, int32_t b = -1); // ops carrying one or two i32

    SimConnection link_;
};

} // namespace caracara
