// The Teensy's poll: one frame a cycle, the three orientation axes, then one distance sensor, in
// turn, carried by the TeensyWorker; no frame is handed over while the last is out (a slow Teensy
// is polled as fast as it answers). An answer goes into the TeensyTelemetry; what became of each
// frame goes to its owner, the TeensyConnection, which judges the link.
#pragma once

#include "daemon/teensy/teensy_telemetry.hpp"
#include "daemon/teensy/teensy_worker.hpp"
#include "drivers/devices/teensy_link.hpp"

#include <functional>

namespace caracara {

class TeensyPoll {
public:
    enum class Outcome {
        Answered, // a valid frame: its value is in the telemetry
        Gone,     // the SPI device went away (ENODEV)
        Failed,   // anything else: busy, no answer, garbage
    };
    // `io_errno(error)`: the failed transfer's errno, on the worker's thread. `done(outcome)`: on
    // the loop thread, after each frame.
    using IoErrno = std::function<int(teensy::TeensyError)>;
    TeensyPoll(TeensyWorker& worker, TeensyLink& link, TeensyTelemetry& tm, IoErrno io_errno,
               std::function<void(Outcome)> done)
        : worker_(worker), link_(link), tm_(tm), io_errno_(std::move(io_errno)), done_(std::move(done)) {}

    // A frame is out: the next waits for its answer.
    bool out() const { return out_; }
    // Hands the next frame to the worker; its result is taken at the worker's next collect().
    void ask();

private:
    void answered(); // loop thread

    TeensyWorker& worker_;
    TeensyLink& link_; // the worker's while it runs
    TeensyTelemetry& tm_;
    IoErrno io_errno_;
    std::function<void(Outcome)> done_;
    unsigned index_ = 0;
    bool out_ = false;
    struct Frame {
        unsigned slot = 0; // 0..2 an orientation axis, 3 a distance sensor
        unsigned sensor = 0;
        bool ok = false;
        double value = 0;
        uint64_t read_ns = 0; // when the answer came (CLOCK_MONOTONIC)
        int err = 0;
    } frame_; // the worker's while a frame is out
};

} // namespace caracara
