// Chooses the hardware behind the seam from caracarad's --hardware argument.
#pragma once

#include "drivers/platform/device_io.hpp"
#include "drivers/platform/gpio_backend.hpp"

#include <memory>
#include <string>

namespace caracara {

struct Hardware {
    std::unique_ptr<DeviceIo> io;
    std::unique_ptr<GpioBackend> gpio;
    // The I2C bus's own seam for the bus worker's thread: a second connection to the
    // simulator, so that a transfer held by a hung device never holds up the GPIO lines
    // (the kill output) or the Teensy behind it. Null on Linux, where `io` is stateless.
    std::unique_ptr<DeviceIo> bus_io_own;
    DeviceIo& bus_io() { return bus_io_own ? *bus_io_own : *io; }
    // The same for the Teensy's SPI frames, carried by the Teensy worker's thread.
    std::unique_ptr<DeviceIo> spi_io_own;
    DeviceIo& spi_io() { return spi_io_own ? *spi_io_own : *io; }
};

// "linux": the kernel's device nodes and libgpiod. "sim:SOCKET": a running caracara-sim.
// Returns false with `error` set on a bad spec or an unreachable simulator.
bool make_hardware(const std::string& spec, Hardware& out, std::string& error);

} // namespace caracara
