// Told which line is the kill output whenever it changes (the fatal-signal emergency stop,
// which writes it first): set before the line is used and cleared before it is destroyed.
#pragma once

#include "drivers/platform/gpio_line.hpp"

namespace caracara {

class KillOutputWatcher {
public:
    virtual ~KillOutputWatcher() = default;
    // The line as its owner holds it now; null while it has none.
    virtual void set_kill_output(GpioLine* line) noexcept = 0;
};

} // namespace caracara
