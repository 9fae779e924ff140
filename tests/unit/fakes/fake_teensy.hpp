// The device seam's SPI side in process: the simulator's own Teensy (sim/TeensyModel, the
// firmware's protocol byte by byte) behind the spidev node [spi] device names, its orientation
// given by the test (`attitude`, asked at each Get orientation, on the Teensy worker's thread).
// Thread-safe: the worker's frames and a test's set_silent are serialised.
#pragma once

#include "core/config.hpp"
#include "drivers/platform/device_io.hpp"
#include "sim/teensy_model.hpp"

#include <cerrno>
#include <mutex>
#include <string>

namespace caracara::test {

class FakeTeensy final : public DeviceIo {
public:
    // `device`: the node as [spi] device names it (the default's unless a test gives another).
    explicit FakeTeensy(sim::TeensyModel::AttitudeSource attitude, std::string device = SpiSettings{}.device);

    int open(const char* path, int flags) override;
    int ioctl(int fd, unsigned long request, void* arg) override;
    int close(int) override { return 0; }
    int write(int, const void*, size_t) override { return -EBADF; }

    // The Teensy stops listening (a hung interrupt: every byte it shifts out is zero, no frame
    // is acknowledged) or listens again.
    void set_silent(bool silent);

private:
    static constexpr int kSpiFd = 5;
    int message(unsigned long request, void* arg);

    const std::string device_;
    std::mutex mu_;
    sim::TeensyModel model_;
    bool silent_ = false;
};

} // namespace caracara::test
