// The commissioning steps as dive events (docs/dive-format.md): a motor test starting, changing
// and stopping, a direction detection run starting and ending, each of its pulses and each
// thruster's verdict. Read from MotorTest and DirectionDetection at every control-loop cycle
// (no hook in them): a motor test also ends by a pilot's command, a kill or its caller leaving,
// and only its state at the cycle says so. An event is stamped at the cycle that saw it, at most
// one loop period after the order it describes went to the bus.
#pragma once

#include "core/dive_format.hpp"
#include "daemon/commissioning/direction_detection.hpp"
#include "daemon/commissioning/motor_test.hpp"
#include "daemon/vehicle/vehicle.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace caracara {

class CommissioningEvents {
public:
    CommissioningEvents(const Vehicle& vehicle, const MotorTest& motor_test, const DirectionDetection& detection);

    // A dive begins: what runs now is news to it.
    void reset();
    // What changed since the last call, in the order it happened (times left for the caller).
    void poll(std::vector<dive::Event>& out);
    // The dive ends: whatever still runs is recorded as ended with it (a kill's zeros end it,
    // though the detection hears of them only at its next step).
    void close(std::vector<dive::Event>& out);

private:
    void motor_test_events(std::vector<dive::Event>& out);
    void detection_events(std::vector<dive::Event>& out);
    void pulse_off(std::vector<dive::Event>& out);
    void detection_end(std::vector<dive::Event>& out);

    const Vehicle& vehicle_;
    const MotorTest& motor_test_;
    const DirectionDetection& detection_;
    int32_t test_thruster_ = -1;
    int32_t test_value_ = 0;
    bool detecting_ = false;
    int32_t pulsing_ = -1;
    std::size_t judged_ = 0;
};

} // namespace caracara
