// A one-shot timer at a monotonic time (ns) that moves: the end of arming and the command
// timeout land on it at the time the safety machine names, not at the next tick of the loop.
#pragma once

#include "drivers/platform/event_loop.hpp"

#include <cstdint>
#include <functional>
#include <limits>
#include <string>

namespace caracara {

class DeadlineTimer final {
public:
    static constexpr uint64_t kNever = std::numeric_limits<uint64_t>::max();

    explicit DeadlineTimer(std::function<void()> fired) : fired_(std::move(fired)) {}
    // Makes the timer, off until arm(). "" or why it could not.
    std::string start(sd_event* event);
    void stop() { source_.reset(); }
    // Fires once at `at_ns` (kNever: not at all). Re-armed only when that time moves: this
    // runs on every cycle.
    void arm(uint64_t at_ns);

private:
    static int on_time(sd_event_source*, uint64_t usec, void* userdata);

    std::function<void()> fired_;
    SourcePtr source_;
    uint64_t at_ = kNever; // what source_ is armed for
};

} // namespace caracara
