// PCA9544A 4-channel I2C multiplexer (NXP data sheet): its one control register is written
// with a single byte: bit 2 enables, bits 1-0 pick the channel; 0x00 disconnects every channel.
// Addresses (0x70..0x77) are in core/thruster_config.hpp, where the configuration checks them.
#pragma once

#include "core/thruster_config.hpp"

#include <cstdint>

namespace caracara {

inline constexpr uint8_t kMuxDisableAll = 0x00;
constexpr uint8_t mux_control_byte(uint8_t channel) { return static_cast<uint8_t>(0x04 | (channel & 0x03)); }

} // namespace caracara
