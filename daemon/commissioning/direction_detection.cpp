#include "daemon/commissioning/direction_detection.hpp"

#include "core/clock.hpp"
#include "daemon/loop/log.hpp"

namespace caracara {

namespace {

constexpr uint64_t kStepNs = 20'000'000; // the Teensy's orientation changes at the loop rate
constexpr uint64_t kMs = 1'000'000;
// The attitude over the end of the pulse: its last 40 %, where the rotation has built up.
constexpr double kMeasureFrom = 0.6;

} // namespace

DirectionDetection::DirectionDetection(const DaemonConfig& config, Vehicle& vehicle, const TeensyPort& teensy,
                                       const FailsafeMonitor& failsafes)
    : config_(config), vehicle_(vehicle), teensy_(teensy), failsafes_(failsafes), timer_([this] { step(); }),
      findings_(config) {}

std::string DirectionDetection::start(sd_event* event) { return timer_.start(event); }

void DirectionDetection::stop() {
    // The daemon's way out zeroes every thruster itself; the caller only hears why it ended.
    timer_.stop();
    phase_ = Phase::Idle;
    if (Completion done = std::move(done_))
        done({Status::Busy, "caracarad is stopping"});
    done_ = nullptr;
}

MotorValues DirectionDetection::pulse_values() const {
    MotorValues m{};
    m[motor_] = config_.commissioning.detect_pulse_value;
    return m;
}

void DirectionDetection::run(std::string_view client, Completion done) {
    if (running()) {
        done({Status::Busy, "a direction detection is running"});
        return;
    }
    if (Result r = vehicle_.state_error(); !r.ok()) {
        done(r);
        return;
    }
    if (!teensy_.telemetry().online) {
        done({Status::LinkError, "the Teensy is offline: its orientation is what detection measures"});
        return;
    }
    // The caller becomes the commanding client with all thrusters at zero.
    if (Result r = vehicle_.motors().drive(MotorValues{}, client); !r.ok()) {
        done(r);
        return;
    }
    client_ = client;
    done_ = std::move(done);
    findings_.clear();
    motor_ = 0;
    phase_ = Phase::Settle;
    phase_start_ns_ = monotonic_ns();
    samples_.clear();
    log_notice("direction detection started by %s", client_.c_str());
    next_step(phase_start_ns_);
}

void DirectionDetection::next_step(uint64_t now) { timer_.arm(now + kStepNs); }

Result DirectionDetection::abort_reason() const {
    if (Result r = vehicle_.state_error(); !r.ok())
        return r;
    if (vehicle_.readings().controller_client() != client_)
        return {Status::Busy, "another command took over the thrusters (or the caller left)"};
    if (!failsafes_.active().empty())
        return {Status::FailsafeActive, "a failsafe is active"};
    if (!teensy_.telemetry().online)
        return {Status::LinkError, "the Teensy went offline"};
    return {};
}

void DirectionDetection::end(Result r) {
    const bool ours = vehicle_.readings().may_drive() && vehicle_.readings().controller_client() == client_;
    phase_ = Phase::Idle;
    timer_.arm(DeadlineTimer::kNever);
    if (ours)
        (void)vehicle_.motors().drive(MotorValues{}, client_);
    if (r.ok())
        log_notice("direction detection done");
    else
        log_warning("direction detection ended: %s", r.message.c_str());
    Completion done = std::move(done_);
    done_ = nullptr;
    if (done)
        done(r);
}

void DirectionDetection::step() {
    if (!running())
        return;
    if (Result r = abort_reason(); !r.ok()) {
        end(r);
        return;
    }
    const uint64_t now = monotonic_ns();
    // Each reading once, at its read time: a stalled poll's last value repeated would look still.
    if (const TeensyTelemetry& tm = teensy_.telemetry(); tm.orientation_polled_ns != 0)
        samples_.add(tm.orientation_polled_ns, tm.orientation);
    if (phase_ == Phase::Settle)
        settle_step(now);
    else
        pulse_step(now);
    if (running())
        next_step(now);
}

void DirectionDetection::settle_step(uint64_t now) {
    const auto& c = config_.commissioning;
    const uint64_t window = uint64_t(c.detect_settle_ms) * kMs;
    // The zeros re-sent, as the pulse is, so the command timeout does not take the caller's
    // place as the commanding client between pulses.
    if (Result r = vehicle_.motors().drive(MotorValues{}, client_); !r.ok()) {
        end(r);
        return;
    }
    samples_.keep_window(window, now);
    // A vertical thruster's pulse (this run's or whatever moved the vehicle before it) leaves
    // pitch and roll swinging back (the vehicle is bottom-heavy); the window is judged only after
    // a rest of two windows.
    // Still: the last half window's mean within detect_settle_mrad of the whole window's.
    if (now - phase_start_ns_ >= 3 * window && samples_.still(now, window / 2, c.detect_settle_mrad / 1000.0)) {
        // The whole window's mean: the sensor's noise averaged over every sample. A slow drift
        // is left in (0.5 mrad/s moves ~1 mrad by the measurement, a tenth of the threshold).
        baseline_ = *samples_.mean_from(0); // still: there are samples
        samples_.clear();
        phase_ = Phase::Pulse;
        phase_start_ns_ = now;
        if (Result r = vehicle_.motors().drive(pulse_values(), client_); !r.ok())
            end(r);
        return;
    }
    if (now - phase_start_ns_ > uint64_t(c.detect_settle_timeout_ms) * kMs)
        end({Status::NotStill, "the vehicle did not hold still within " + std::to_string(c.detect_settle_timeout_ms) +
                                   " ms before thruster " + std::to_string(motor_) + "'s pulse"});
}

void DirectionDetection::pulse_step(uint64_t now) {
    const auto& c = config_.commissioning;
    const uint64_t length = uint64_t(c.detect_pulse_ms) * kMs;
    if (now - phase_start_ns_ < length) {
        // Re-sent each step so the command timeout does not stop the pulse early.
        if (Result r = vehicle_.motors().drive(pulse_values(), client_); !r.ok())
            end(r);
        return;
    }
    if (Result r = vehicle_.motors().drive(MotorValues{}, client_); !r.ok()) {
        end(r);
        return;
    }
    const auto after = samples_.mean_from(phase_start_ns_ + uint64_t(double(length) * kMeasureFrom));
    if (!after) {
        end({Status::LinkError, "the Teensy gave no orientation reading over the end of thruster " +
                                    std::to_string(motor_) + "'s pulse"});
        return;
    }
    findings_.record(motor_, AttitudeSamples::change(baseline_, *after));
    samples_.clear();
    if (++motor_ >= kMotorCount) {
        end({});
        return;
    }
    phase_ = Phase::Settle;
    phase_start_ns_ = now;
}

} // namespace caracara
