// GPIO lines behind one small interface, so the libgpiod v1/v2 difference and the simulator
// stay below it: inputs (optionally with edge events for the sd-event loop), push-pull and
// open-drain outputs. Values are logical: active_low is applied by the backend.
#pragma once

#include "sim_protocol.hpp"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

namespace caracara {

using simproto::GpioMode;

struct GpioLineSpec {
    std::string chip = "gpiochip0"; // name or path of the chip
    std::string name;                // line name; used when offset is not set
    std::optional<uint32_t> offset;
    bool active_low = false;
    std::string describe() const;    // "gpiochip0:GPIO17" / "gpiochip0 line 17"
};

class GpioLine {
public:
    virtual ~GpioLine() = default;
    virtual int get() = 0;          // logical 0/1, or -errno
    virtual int set(int value) = 0; // logical; 0 or -errno (open drain: 1 releases the line)
    // InputEdges only: readable when edges arrived; drain_events() consumes them and returns
    // how many, or -errno. -1 for other modes.
    virtual int event_fd() const { return -1; }
    virtual int drain_events() { return 0; }
};

class GpioBackend {
public:
    virtual ~GpioBackend() = default;
    // Requests the line; nullptr with `error` set when it cannot be had.
    virtual std::unique_ptr<GpioLine> request(const GpioLineSpec& spec, GpioMode mode, int initial,
                                              std::string& error) = 0;
};

// libgpiod 1.6 (Debian 12) on the real chips.
std::unique_ptr<GpioBackend> make_libgpiod_backend(const std::string& consumer);

} // namespace caracara
