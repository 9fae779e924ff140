// Shared by every GpioBackend (libgpiod v1 or v2, the simulator): how errors name a line.
#include "drivers/platform/gpio_line.hpp"

namespace caracara {

std::string GpioLineSpec::describe() const {
    return offset ? chip + " line " + std::to_string(*offset) : chip + ":" + name;
}

} // namespace caracara
