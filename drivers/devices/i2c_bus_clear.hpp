// I2C bus clear (NXP UM10204 3.1.16, Linux i2c_generic_scl_recovery): with SCL and SDA taken
// as open-drain GPIO lines, clock SCL up to nine times, no faster than 100 kHz, until the
// stuck slave releases SDA, then generate a STOP. If SCL itself is held low, clocking cannot
// help. Also the sysfs bind/unbind writes that give the pins back to the I2C controller.
#pragma once

#include "drivers/platform/device_io.hpp"
#include "drivers/platform/gpio_backend.hpp"

#include <cstdint>
#include <string>

namespace caracara {

struct BusClearResult {
    enum class Outcome { Cleared, SclHeldLow, SdaStillLow, GpioError } outcome = Outcome::GpioError;
    unsigned pulses = 0;  // SCL clocks generated
    std::string message;
    bool ok() const { return outcome == Outcome::Cleared; }
};

// half_period_ns >= 5000 keeps the clock at or below 100 kHz.
BusClearResult i2c_bus_clear(GpioBackend& gpio, const GpioLineSpec& scl, const GpioLineSpec& sda,
                             uint32_t half_period_ns = 5000);

// Writes `text` to a sysfs attribute (e.g. a driver's bind/unbind); 0 or -errno.
int sysfs_write(DeviceIo& io, const std::string& path, const std::string& text);

} // namespace caracara
