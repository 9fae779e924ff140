#pragma once

#include "sim/i2c_slave.hpp"

#include <cstdint>
#include <optional>
#include <span>

namespace caracara::sim {

// PCA9544A: one control byte, bit 2 enables, bits 0-1 pick the downstream channel.
class Pca9544 final : public I2cSlave {
public:
    bool ack_address(bool) override { return true; }
    void on_write(std::span<const uint8_t> data, uint64_t) override;
    void on_read(std::span<uint8_t> out, uint64_t) override;
    std::optional<uint8_t> selected() const;
    uint8_t control() const { return control_; }

private:
    uint8_t control_ = 0; // power-on: no channel selected
};

} // namespace caracara::sim
