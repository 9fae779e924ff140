// What the Teensy last told: its orientation, distances, servos, and whether it answers.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace caracara {

struct TeensyTelemetry {
    bool online = false;
    std::array<double, 3> orientation{}; // yaw, pitch, roll
    std::vector<uint16_t> distances;
    std::vector<uint8_t> servos;
    bool turning = false;
};

} // namespace caracara
