// A configured GPIO line (core/config) as the GPIO backend asks for it.
#pragma once

#include "core/config.hpp"
#include "drivers/platform/gpio_line.hpp"

namespace caracara {

inline GpioLineSpec line_spec(const GpioLineSettings& s) {
    GpioLineSpec spec;
    spec.chip = s.chip;
    spec.name = s.name;
    spec.offset = s.offset;
    spec.active_low = s.active_low;
    return spec;
}

} // namespace caracara
