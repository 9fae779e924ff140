// The zeroing step systemd runs after every end of caracarad (ExecStopPost=, as
// `caracarad --zero-thrusters`): the kill output asserted first, then zero to every configured
// thruster through the same drivers and mux handling as the daemon, then Stop to the Teensy's
// wheels. Bounded: once the bus shows itself locked (the daemon's own lockup rule) the
// remaining thrusters are reported unreachable instead of each waiting out its timeout.
#pragma once

#include "core/config.hpp"
#include "drivers/platform/device_io.hpp"
#include "drivers/platform/gpio_backend.hpp"

#include <string>
#include <vector>

namespace caracara {

class FinalStop {
public:
    struct Report {
        bool kill_output_asserted = false;  // false also when none is configured
        std::vector<std::string> problems;  // one line per thing that could not be done
        unsigned zeroed = 0;                // thrusters that ACKed the zero order
        bool ok() const { return problems.empty(); }
    };

    FinalStop(const DaemonConfig& config, DeviceIo& io, GpioBackend& gpio) : config_(config), io_(io), gpio_(gpio) {}
    Report run();

private:
    void assert_kill_output(Report& r);
    void zero_thrusters(Report& r);
    void stop_wheels(Report& r);

    const DaemonConfig& config_;
    DeviceIo& io_;
    GpioBackend& gpio_;
};

} // namespace caracara
