// The simulator's GPIO backend (see gpio_sim.cpp).
#pragma once

#include "drivers/platform/io_error.hpp"
#include "drivers/platform/gpio_backend.hpp"
#include "drivers/platform/sim/sim_device_io.hpp"

namespace caracara {

std::unique_ptr<GpioBackend> make_sim_gpio_backend(SimDeviceIo& io);

} // namespace caracara
