// The simulated Teensy's (sim/teensy_model) wheel formula, turn rate, servos, distance sensors
// and frame log size.
#pragma once

#include <cstddef>
#include <cstdint>

namespace caracara::sim {

struct TeensyConfig {
    // Rear-wheel formula v3/4 = k * Df/Db * ((v1 + v2)/2 +- (v2 - v1)).
    double wheel_k = 0.8;
    double front_circumference = 1.0; // Df, any unit (only the ratio matters)
    double back_circumference = 1.0;  // Db
    double turn_rate_rad_s = 1.0;
    std::size_t servo_count = 4;
    std::size_t distance_sensor_count = 4;
    uint8_t servo_initial_degrees = 90;
    uint16_t distance_initial_mm = 1000;
    std::size_t log_capacity = 256;
};

} // namespace caracara::sim
