// i2c-dev access through the device seam: one I2C_RDWR per transaction, exactly the
// struct i2c_msg array the SBC's kernel receives (bcm2835 allows only one read, last).
#pragma once

#include "drivers/platform/device_io.hpp"
#include "drivers/platform/io_error.hpp"

#include <cstdint>
#include <optional>
#include <linux/i2c.h>
#include <span>
#include <string>

namespace caracara {

class I2cDev {
public:
    // The adapter's transfer timeout and retries (I2C_TIMEOUT, I2C_RETRIES), applied at every
    // open; unset: the kernel's defaults (i2c-bcm2835 waits one second).
    struct Limits {
        std::optional<uint32_t> timeout_ms;
        std::optional<uint32_t> retries;
    };
    I2cDev(DeviceIo& io, std::string path, Limits limits = {}) : io_(io), path_(std::move(path)), limits_(limits) {}
    ~I2cDev() { close(); }
    I2cDev(const I2cDev&) = delete;
    I2cDev& operator=(const I2cDev&) = delete;

    // Opens the node and checks I2C_FUNCS for plain I2C (I2C_FUNC_I2C). Returns -errno
    // (-EOPNOTSUPP when the adapter cannot do plain I2C transfers).
    int open();
    void close();
    bool is_open() const { return fd_ >= 0; }
    const std::string& path() const { return path_; }

    // One I2C_RDWR ioctl carrying `msgs`. Returns IoError::None or the typed failure;
    // last_errno() keeps the raw errno of the last failure.
    IoError transfer(std::span<i2c_msg> msgs);
    IoError write(uint16_t addr7, std::span<const uint8_t> data);
    IoError read(uint16_t addr7, std::span<uint8_t> data);
    int last_errno() const { return last_errno_; }

private:
    DeviceIo& io_;
    std::string path_;
    Limits limits_;
    int fd_ = -1;
    int last_errno_ = 0;
};

} // namespace caracara
