// GPIO lines behind one small interface, so the libgpiod v1/v2 difference and the simulator
// stay below it: inputs (optionally with edge events for the sd-event loop), push-pull and
// open-drain outputs. Values are logical: active_low is applied by the backend.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace caracara {

enum class GpioMode : uint8_t {
    Input,
    InputEdges, // input with both-edge events
    Output,     // push-pull
    OpenDrain,  // drives low or releases; reading returns the wire
};

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
    // Sets an output from a fatal-signal handler: async-signal-safe (one ioctl or one send, no
    // allocation, no lock) where the backend can do it; false where it cannot.
    virtual bool set_in_signal_handler(int value) noexcept {
        (void)value;
        return false;
    }
};

} // namespace caracara
