// libgpiod on the real chips. Defined by libgpiod_backend.cpp on libgpiod 1.6 (Debian 12, Raspberry
// Pi OS bookworm) or libgpiod2_backend.cpp on libgpiod 2 (Debian 13, Raspberry Pi OS trixie):
// CMake builds the one for the libgpiodcxx that pkg-config finds; both behave the same.
#pragma once

#include "drivers/platform/gpio_backend.hpp"

#include <memory>
#include <string>

namespace caracara {

std::unique_ptr<GpioBackend> make_libgpiod_backend(const std::string& consumer);

} // namespace caracara
