// What the Teensy last told: its orientation, distances, servos, and whether it answers.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace caracara {

struct TeensyTelemetry {
    bool online = false;
    std::array<double, 3> orientation{}; // yaw, pitch, roll
    // CLOCK_MONOTONIC ns of the reading that last changed `orientation` (0: none yet): what the
    // announced value is as of, for a client that stamps it (caracara-ros's Imu and /tf).
    uint64_t orientation_read_ns = 0;
    // CLOCK_MONOTONIC ns of the last orientation reading, changed or not (0: none yet): whether a
    // reading is new, for direction detection, which must not take a stalled poll's last value
    // for a vehicle holding still.
    uint64_t orientation_polled_ns = 0;
    std::vector<uint16_t> distances;
    std::vector<uint8_t> servos;
    bool turning = false;
};

} // namespace caracara
