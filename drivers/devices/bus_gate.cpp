#include "drivers/devices/bus_gate.hpp"

#include <ctime>
#include <unistd.h>

namespace caracara {

bool BusGate::enter(pid_t self) noexcept {
    // Announce first, then look (both sequentially consistent): either the handler sees us
    // inside and waits, or we see it closed and stay out.
    inside_.store(self);
    if (closed_.load()) {
        inside_.store(0);
        return false;
    }
    return true;
}

bool BusGate::wait_clear(int max_wait_ms) const noexcept {
    const pid_t self = ::gettid();
    const timespec step{0, 100 * 1000}; // 100 us: an order at 100 kHz takes about 400
    for (int waited_us = 0; waited_us < max_wait_ms * 1000; waited_us += 100) {
        const pid_t in = inside_.load();
        if (in == 0)
            return true;
        if (in == self)
            return false;
        nanosleep(&step, nullptr);
    }
    return inside_.load() == 0;
}

} // namespace caracara
