// Chooses the hardware behind the seam from caracarad's --hardware argument.
#pragma once

#include "platform/device_io.hpp"
#include "platform/gpio_backend.hpp"

#include <memory>
#include <string>

namespace caracara {

struct Hardware {
    std::unique_ptr<DeviceIo> io;
    std::unique_ptr<GpioBackend> gpio;
};

// "linux": the kernel's device nodes and libgpiod. "sim:SOCKET": a running caracara-sim.
// Returns false with `error` set on a bad spec or an unreachable simulator.
bool make_hardware(const std::string& spec, Hardware& out, std::string& error);

} // namespace caracara
