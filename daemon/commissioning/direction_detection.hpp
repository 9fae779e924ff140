// Thruster direction detection (docs/commissioning.md; ArduSub's motor detection on our
// mixing): armed, in the water; for each thruster in turn it waits until the vehicle holds
// still (after a rest, the Teensy's readings over detect_settle_ms: AttitudeSamples), takes that
// attitude, pulses the thruster alone (detect_pulse_value for detect_pulse_ms, through
// MotorCommands::drive like any motor command), takes the attitude over the end of the pulse,
// orders it zero, and has core/direction_judgement say ok, reversed or inconclusive. It never
// changes the configuration: the caller gets the fragment. A kill, the caller leaving or another
// pilot commanding, a failsafe, a vehicle that will not settle or a Teensy that gives no reading
// ends it with the error (the kill's zeros are the kill's own, at once).
#pragma once

#include "core/config.hpp"
#include "core/status.hpp"
#include "daemon/commissioning/attitude_samples.hpp"
#include "daemon/commissioning/direction_findings.hpp"
#include "daemon/failsafe/failsafe_monitor.hpp"
#include "daemon/loop/completion.hpp"
#include "daemon/loop/deadline_timer.hpp"
#include "daemon/teensy/teensy_port.hpp"
#include "daemon/vehicle/vehicle.hpp"
#include "drivers/platform/event_loop.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace caracara {

class DirectionDetection final {
public:
    DirectionDetection(const DaemonConfig& config, Vehicle& vehicle, const TeensyPort& teensy,
                       const FailsafeMonitor& failsafes);
    std::string start(sd_event* event); // the step timer; "" or why it could not
    void stop();

    // Runs the detection for `client`; `done` gets its end (Ok with findings() filled, or the
    // error that ended it). Busy while one runs.
    void run(std::string_view client, Completion done);
    bool running() const { return phase_ != Phase::Idle; }
    // The thruster being pulsed now, or -1.
    int32_t pulsing() const { return phase_ == Phase::Pulse ? static_cast<int32_t>(motor_) : -1; }
    const std::array<DirectionFinding, kMotorCount>& findings() const { return findings_.all(); }
    // How many thrusters this run (or the last) judged: findings()[0, judged()) are its verdicts.
    std::size_t judged() const { return motor_; }
    std::string fragment() const { return findings_.fragment(); }

private:
    enum class Phase : uint8_t { Idle, Settle, Pulse };

    void step();
    void settle_step(uint64_t now);
    void pulse_step(uint64_t now);
    void end(Result r);
    Result abort_reason() const;
    void next_step(uint64_t now);
    MotorValues pulse_values() const;

    const DaemonConfig& config_;
    Vehicle& vehicle_;
    const TeensyPort& teensy_;
    const FailsafeMonitor& failsafes_;
    DeadlineTimer timer_;
    Phase phase_ = Phase::Idle;
    std::size_t motor_ = 0;
    std::string client_;
    Completion done_;
    uint64_t phase_start_ns_ = 0;
    AttitudeSamples samples_;
    AttitudeSamples::Attitude baseline_{}; // rad: the still window's mean
    DirectionFindings findings_;
};

} // namespace caracara
