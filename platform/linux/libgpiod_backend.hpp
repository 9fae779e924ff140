// libgpiod 1.6 (Debian 12) on the real chips.
#pragma once

#include "platform/gpio_backend.hpp"

#include <memory>
#include <string>

namespace caracara {

std::unique_ptr<GpioBackend> make_libgpiod_backend(const std::string& consumer);

} // namespace caracara
