// The commissioning steps as dive events (docs/dive-format.md): a motor test starting, changing
// and stopping, a direction detection run starting and ending, each of its pulses and each
// thruster's verdict. Read from MotorTest and DirectionDetection at every control-loop cycle: a
// motor test also ends by a pilot's command, a kill or its caller leaving, and only its state at
// the cycle says so; such an event is stamped at the cycle that saw it, at most one loop period
// after the order it describes went to the bus. A motor test's start MotorTest tells at once.
#pragma once

#include "core/dive_format.hpp"
#include "daemon/commissioning/direction_detection.hpp"
#include "daemon/commissioning/motor_test.hpp"
#include "daemon/vehicle/vehicle.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace caracara {

class CommissioningEvents {
public:
    CommissioningEvents(const Vehicle& vehicle, const MotorTest& motor_test, const DirectionDetection& detection);

    // A dive begins: what runs now is news to it.
    void reset();
    // Encodes into `records` what changed since the last call, in the order it happened, stamped
    // `t_100us` (the dive's time now).
    void record(std::vector<uint8_t>& records, uint32_t t_100us);
    // The dive ends: whatever still runs is recorded as ended with it (a kill's zeros end it,
    // though the detection hears of them only at its next step).
    void close(std::vector<uint8_t>& records, uint32_t t_100us);
    // A motor test's order accepted now (MotorTest tells it at once: a test replaced within a
    // cycle is in the dive too); the same test repeated (its keep-alive) records nothing.
    void motor_test(std::vector<uint8_t>& records, uint32_t t_100us, int32_t thruster, int32_t value);

private:
    void emit(dive::EventKind kind, int32_t thruster, uint32_t value, double number, std::string text = {},
              std::string client = {});
    void motor_test_events();
    void test_now(int32_t thruster, int32_t value);
    void detection_events();
    void pulse_off();
    void detection_end();

    const Vehicle& vehicle_;
    const MotorTest& motor_test_;
    const DirectionDetection& detection_;
    int32_t test_thruster_ = -1;
    int32_t test_value_ = 0;
    bool detecting_ = false;
    int32_t pulsing_ = -1;
    std::size_t judged_ = 0;
    std::vector<uint8_t>* records_ = nullptr; // during record() and close()
    uint32_t t_100us_ = 0;
};

} // namespace caracara
