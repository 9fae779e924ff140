// The device seam's SPI side in process: the Teensy's node, served by the simulator's own
// Teensy (sim/TeensyModel), which gets each SPI_IOC_MESSAGE byte for byte as caracara-sim hands
// it over, so the daemon's Teensy units talk the real protocol to it. A test makes the node go
// away (ENODEV on a descriptor open before, ENOENT on open) and come back, holds the frames on
// the wire (a hung Teensy), and reaches the model (its faults, its frame log) through model().
// Thread-safe: the Teensy worker calls from its own thread.
#pragma once

#include "drivers/platform/device_io.hpp"
#include "sim/teensy_model.hpp"

#include <cerrno>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>

namespace caracara::test {

class FakeTeensyIo final : public DeviceIo {
public:
    explicit FakeTeensyIo(std::string device);

    int open(const char* path, int flags) override;
    int ioctl(int fd, unsigned long request, void* arg) override;
    int close(int) override { return 0; }
    int write(int, const void*, size_t) override { return -EBADF; }

    // The node goes away (every descriptor open so far is dead) or comes back.
    void set_gone(bool gone);
    // While held, a frame that reaches the wire waits there (a hung Teensy).
    void hold(bool held);
    // The attitude the model's orientation sensor reads (the body's; 0 at first).
    void set_attitude(const sim::BodyAttitude& a);
    // `f` with the model, under the lock the worker's frames take.
    void model(const std::function<void(sim::TeensyModel&)>& f);
    // The model's frame log: frames of `command` received and executed, and all frames so far.
    uint64_t received(uint8_t command);
    uint64_t executed(uint8_t command);
    uint64_t frames();

private:
    std::mutex mu_;
    std::condition_variable released_;
    std::string device_;
    sim::BodyAttitude attitude_; // read by the model under the lock
    sim::TeensyModel model_;
    bool gone_ = false;
    bool held_ = false;
    int next_fd_ = 100; // each open a descriptor of its own
    int live_from_ = 100; // descriptors below this went with the node
    uint64_t stepped_ns_ = 0;
};

} // namespace caracara::test
