// The device seam's I2C side in process: a DeviceIo whose adapter is eight SeaBotix thrusters
// at the configured addresses (on the trunk; a mux select is taken and ignored). Orders and
// status reads land on a FakeWire; a status read gets a reply with the FAULT bits the wire
// holds for it (none unless a test sets them); on a locked wire every transfer times out. Other
// devices (the Teensy's SPI, sysfs) are absent. Thread-safe, like the kernel.
#pragma once

#include "core/config.hpp"
#include "drivers/platform/device_io.hpp"
#include "tests/unit/fakes/fake_wire.hpp"

#include <string>

namespace caracara::test {

class FakeDeviceIo final : public DeviceIo {
public:
    FakeDeviceIo(FakeWire& wire, const DaemonConfig& config) : wire_(wire), config_(config) {}

    int open(const char* path, int flags) override;
    int ioctl(int fd, unsigned long request, void* arg) override;
    int close(int) override { return 0; }
    int write(int, const void*, size_t len) override { return static_cast<int>(len); }

private:
    static constexpr int kAdapterFd = 3;
    int transfer(void* arg);

    FakeWire& wire_;
    const DaemonConfig& config_;
};

} // namespace caracara::test
