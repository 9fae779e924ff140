// Where GPIO lines come from: libgpiod on the real chips (drivers/platform/linux/) or caracara-sim
// (drivers/platform/sim/).
#pragma once

#include "drivers/platform/gpio_line.hpp"

#include <memory>
#include <string>

namespace caracara {

class GpioBackend {
public:
    virtual ~GpioBackend() = default;
    // Requests the line; nullptr with `error` set when it cannot be had.
    virtual std::unique_ptr<GpioLine> request(const GpioLineSpec& spec, GpioMode mode, int initial,
                                              std::string& error) = 0;
};


} // namespace caracara
