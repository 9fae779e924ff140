// Asking again for a Teensy SPI device that is not there (absent at start, or gone with ENODEV),
// once a second until it opens. The node is opened on the TeensyWorker: it may still be closing
// the old descriptor. Quiet while it fails: its owner logs once when it went, once when it is back.
#pragma once

#include "daemon/teensy/teensy_worker.hpp"
#include "drivers/platform/event_loop.hpp"
#include "drivers/platform/spi_dev.hpp"

#include <functional>

namespace caracara {

class TeensyReopen {
public:
    // `is_open()`: the loop's view (nothing to ask for when open); `reopened()`: the device opened
    // again (loop thread).
    TeensyReopen(sd_event* event, TeensyWorker& worker, SpiDev& spi, std::function<bool()> is_open,
                 std::function<void()> reopened)
        : event_(event), worker_(worker), spi_(spi), is_open_(std::move(is_open)), reopened_(std::move(reopened)) {}

    // Asks for the device again in a second.
    void schedule();
    // No more asking (the connection closes).
    void stop() { timer_.reset(); }

private:
    static int on_timer(sd_event_source*, uint64_t usec, void* userdata);

    sd_event* event_;
    TeensyWorker& worker_;
    SpiDev& spi_; // the worker's while it runs
    std::function<bool()> is_open_;
    std::function<void()> reopened_;
    SourcePtr timer_;
};

} // namespace caracara
