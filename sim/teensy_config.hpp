// The simulated Teensy's (sim/teensy_model) wheel formula, turn rate, servos, distance sensors
// frame log size and the orientation sensor's noise and drift.
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
    // The orientation sensor's imperfections, so that commissioning (direction detection) is
    // proven against a sensor that is not the body's truth: white noise on each angle
    // (standard deviation, rad) and a slow heading drift (rad/s) accumulated over time.
    double orientation_noise_rad = 0.0;
    double yaw_drift_rad_s = 0.0;
    uint64_t noise_seed = 1;
};

} // namespace caracara::sim
