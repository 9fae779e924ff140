// The simulated Teensy's (sim/teensy_model) four wheel speeds.
#pragma once


namespace caracara::sim {

// Front speeds as commanded (int8), back speeds from the formula (may exceed int8 range).
struct TeensyWheels {
    double front_left = 0.0;
    double front_right = 0.0;
    double back_left = 0.0;
    double back_right = 0.0;
};

} // namespace caracara::sim
