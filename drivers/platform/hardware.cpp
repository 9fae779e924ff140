#include "drivers/platform/hardware.hpp"

#include "drivers/platform/io_error.hpp"
#include "drivers/platform/linux/libgpiod_backend.hpp"
#include "drivers/platform/linux/linux_device_io.hpp"
#include "drivers/platform/sim/sim_gpio_backend.hpp"
#include "drivers/platform/sim/sim_device_io.hpp"

namespace caracara {

bool make_hardware(const std::string& spec, Hardware& out, std::string& error) {
    if (spec == "linux") {
        out.io = std::make_unique<LinuxDeviceIo>();
        out.gpio = make_libgpiod_backend("caracarad");
        return true;
    }
    if (spec.rfind("sim:", 0) == 0 && spec.size() > 4) {
        auto io = std::make_unique<SimDeviceIo>();
        if (int r = io->connect(spec.substr(4)); r < 0) {
            error = "cannot connect to caracara-sim at " + spec.substr(4) + ": " + errno_name(-r);
            return false;
        }
        auto bus_io = std::make_unique<SimDeviceIo>();
        auto spi_io = std::make_unique<SimDeviceIo>();
        for (SimDeviceIo* c : {bus_io.get(), spi_io.get()})
            if (int r = c->connect(spec.substr(4)); r < 0) {
                error = "cannot connect to caracara-sim at " + spec.substr(4) + ": " + errno_name(-r);
                return false;
            }
        out.gpio = make_sim_gpio_backend(*io);
        out.io = std::move(io);
        out.bus_io_own = std::move(bus_io);
        out.spi_io_own = std::move(spi_io);
        return true;
    }
    error = "--hardware must be 'linux' or 'sim:SOCKET', got '" + spec + "'";
    return false;
}

} // namespace caracara
