// Which simulated thruster (sim/thruster_model): its variant, address and where it sits behind
// the mux.
#pragma once

#include <cstdint>
#include <optional>

namespace caracara::sim {

enum class ThrusterVariant { SeaBotix, Legacy };

struct ThrusterSpec {
    uint8_t mt = 0x52;                 // 8-bit write address byte
    ThrusterVariant variant = ThrusterVariant::SeaBotix;
    std::optional<uint16_t> mux_addr;  // 7-bit address of the PCA9544A in front of it
    uint8_t mux_channel = 0;
    bool brushless = true;
};

} // namespace caracara::sim
