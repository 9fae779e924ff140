#include "drivers/devices/final_stop.hpp"

#include "core/lockup_detector.hpp"
#include "drivers/devices/mux_tracker.hpp"
#include "drivers/devices/teensy_link.hpp"
#include "drivers/devices/thruster_driver.hpp"
#include "drivers/platform/i2c_dev.hpp"
#include "drivers/platform/io_error.hpp"
#include "drivers/platform/line_spec.hpp"
#include "drivers/platform/spi_dev.hpp"

#include <memory>

namespace caracara {

FinalStop::Report FinalStop::run() {
    Report r;
    assert_kill_output(r); // before any bus transfer: a hung bus must not delay it
    zero_thrusters(r);
    stop_wheels(r);
    return r;
}

void FinalStop::assert_kill_output(Report& r) {
    if (!config_.gpio.kill_output)
        return;
    std::string err;
    // The line is released again when this process exits; wiring decides what it reads then
    // (docs/install.md).
    auto line = gpio_.request(line_spec(*config_.gpio.kill_output), GpioMode::Output, 1, err);
    if (!line) {
        r.problems.push_back("kill output: " + err);
        return;
    }
    r.kill_output_asserted = true;
}

void FinalStop::zero_thrusters(Report& r) {
    I2cDev i2c(io_, config_.i2c.device, {config_.i2c.timeout_ms, config_.i2c.retries});
    if (int e = i2c.open(); e < 0) {
        r.problems.push_back("I2C bus " + config_.i2c.device + ": " + errno_name(-e) + "; no thruster zeroed");
        return;
    }
    MuxTracker mux;
    std::vector<std::unique_ptr<ThrusterDriver>> drivers;
    for (const auto& tc : config_.thrusters)
        drivers.push_back(std::make_unique<ThrusterDriver>(i2c, mux, tc));
    LockupDetector lockup(static_cast<uint32_t>(drivers.size()));
    bool locked = false;
    for (size_t i = 0; i < drivers.size(); ++i) {
        const std::string name = "thruster " + std::to_string(i);
        if (locked) {
            r.problems.push_back(name + ": not tried, the bus is locked");
            continue;
        }
        const IoError e = drivers[i]->send_order(0);
        if (e == IoError::None) {
            ++r.zeroed;
        } else {
            r.problems.push_back(name + ": " + std::string(io_error_name(e)));
        }
        locked = lockup.note(lockup_transfer(e));
    }
}

void FinalStop::stop_wheels(Report& r) {
    SpiDev spi(io_, config_.spi.device, config_.spi.spi);
    if (spi.open() < 0)
        return; // no Teensy: nothing to stop (the daemon runs without one too)
    TeensyLink link(spi, config_.spi.teensy);
    if (auto e = link.stop(0); e != teensy::TeensyError::None)
        r.problems.push_back("Teensy Stop: " + std::string(teensy::teensy_error_name(e)));
}

} // namespace caracara
