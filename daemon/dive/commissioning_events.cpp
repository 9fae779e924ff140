#include "daemon/dive/commissioning_events.hpp"

#include <cstdio>

namespace caracara {

CommissioningEvents::CommissioningEvents(const Vehicle& vehicle, const MotorTest& motor_test,
                                         const DirectionDetection& detection)
    : vehicle_(vehicle), motor_test_(motor_test), detection_(detection) {}

void CommissioningEvents::reset() {
    test_thruster_ = -1;
    test_value_ = 0;
    detecting_ = false;
    pulsing_ = -1;
    judged_ = 0;
}

void CommissioningEvents::emit(dive::EventKind kind, int32_t thruster, uint32_t value, double number,
                               std::string text, std::string client) {
    dive::Event e;
    e.t_100us = t_100us_;
    e.kind = kind;
    e.thruster = static_cast<uint8_t>(thruster < 0 ? 0 : thruster);
    e.value = value;
    e.number = static_cast<float>(number);
    e.text = std::move(text);
    e.client = std::move(client);
    dive::encode_event(*records_, e);
}

void CommissioningEvents::record(std::vector<uint8_t>& records, uint32_t t_100us) {
    records_ = &records;
    t_100us_ = t_100us;
    motor_test_events();
    detection_events();
    records_ = nullptr;
}

void CommissioningEvents::close(std::vector<uint8_t>& records, uint32_t t_100us) {
    record(records, t_100us); // what changed since the last cycle (a run that ended just before the kill)
    records_ = &records;
    if (test_thruster_ >= 0)
        emit(dive::EventKind::MotorTest, test_thruster_, 0, 0);
    test_thruster_ = -1;
    test_value_ = 0;
    if (detecting_)
        detection_end();
    records_ = nullptr;
}

void CommissioningEvents::motor_test(std::vector<uint8_t>& records, uint32_t t_100us, int32_t thruster, int32_t value) {
    records_ = &records;
    t_100us_ = t_100us;
    test_now(thruster, value);
    records_ = nullptr;
}

// A test that stops shows only here (a kill, a pilot's command, its caller leaving, the keep-alive).
void CommissioningEvents::motor_test_events() { test_now(motor_test_.active_thruster(), motor_test_.value()); }

void CommissioningEvents::test_now(int32_t thruster, int32_t value) {
    if (thruster == test_thruster_ && value == test_value_)
        return;
    // A test moved to another thruster: the first one stopped.
    if (test_thruster_ >= 0 && thruster >= 0 && thruster != test_thruster_)
        emit(dive::EventKind::MotorTest, test_thruster_, 0, 0);
    if (thruster >= 0)
        emit(dive::EventKind::MotorTest, thruster, dive::kOn, value, {}, vehicle_.readings().controller_client());
    else
        emit(dive::EventKind::MotorTest, test_thruster_, 0, 0);
    test_thruster_ = thruster;
    test_value_ = value;
}

void CommissioningEvents::pulse_off() {
    emit(dive::EventKind::DetectionPulse, pulsing_, 0, 0);
    pulsing_ = -1;
}

void CommissioningEvents::detection_end() {
    if (pulsing_ >= 0)
        pulse_off();
    emit(dive::EventKind::Detection, 0, 0, double(judged_));
    detecting_ = false;
}

void CommissioningEvents::detection_events() {
    const bool running = detection_.running();
    if (running && !detecting_) {
        detecting_ = true;
        judged_ = 0;
        // The caller is the commanding client from the run's start.
        emit(dive::EventKind::Detection, 0, dive::kOn, 0, {}, vehicle_.readings().controller_client());
    }
    if (!detecting_)
        return;
    const int32_t pulsing = detection_.pulsing();
    if (pulsing != pulsing_ && pulsing_ >= 0)
        pulse_off();
    // The findings of this run: a verdict for each thruster judged since the last cycle.
    for (; judged_ < detection_.judged() && judged_ < kMotorCount; ++judged_) {
        const DirectionFinding& f = detection_.findings()[judged_];
        char text[128];
        std::snprintf(text, sizeof text, "yaw=%+.4f pitch=%+.4f roll=%+.4f along=%+.4f", f.change[0], f.change[1],
                      f.change[2], f.judgement.along);
        emit(dive::EventKind::DetectionResult, static_cast<int32_t>(judged_),
             static_cast<uint32_t>(f.judgement.verdict), f.judgement.margin, text);
    }
    if (pulsing >= 0 && pulsing != pulsing_) {
        pulsing_ = pulsing;
        // The value the detection orders (requested: the budget may scale what is applied).
        emit(dive::EventKind::DetectionPulse, pulsing, dive::kOn,
             vehicle_.readings().requested_values()[static_cast<std::size_t>(pulsing)]);
    }
    if (!running)
        detection_end();
}

} // namespace caracara
