// The simulator's GPIO backend (see gpio_sim.cpp).
#pragma once

#include "errors.hpp"
#include "gpio.hpp"
#include "sim_device_io.hpp"

namespace caracara {

std::unique_ptr<GpioBackend> make_sim_gpio_backend(SimDeviceIo& io);

} // namespace caracara
