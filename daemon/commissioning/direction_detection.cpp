#include "daemon/commissioning/direction_detection.hpp"

#include "core/clock.hpp"
#include "daemon/loop/log.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace caracara {

namespace {

constexpr uint64_t kStepNs = 20'000'000; // the Teensy's orientation changes at the loop rate
constexpr uint64_t kMs = 1'000'000;
// The attitude over the end of the pulse: its last 40 %, where the rotation has built up.
constexpr double kMeasureFrom = 0.6;

double wrap(double a) {
    double r = std::remainder(a, 2.0 * std::numbers::pi);
    return r <= -std::numbers::pi ? r + 2.0 * std::numbers::pi : r;
}

// Mean attitude of the samples from `from_ns` on; yaw averaged as offsets from the first sample so
// a heading near +-pi does not average to zero.
std::array<double, 3> mean_from(const auto& samples, uint64_t from_ns) {
    std::array<double, 3> sum{};
    std::size_t n = 0;
    double ref = 0.0;
    for (const auto& s : samples) {
        if (s.t_ns < from_ns)
            continue;
        if (n == 0)
            ref = s.att[0];
        sum[0] += wrap(s.att[0] - ref);
        sum[1] += s.att[1];
        sum[2] += s.att[2];
        ++n;
    }
    if (n == 0)
        return {};
    return {wrap(ref + sum[0] / double(n)), sum[1] / double(n), sum[2] / double(n)};
}

} // namespace

DirectionDetection::DirectionDetection(const DaemonConfig& config, Vehicle& vehicle, const TeensyPort& teensy,
                                       const FailsafeMonitor& failsafes)
    : config_(config), vehicle_(vehicle), teensy_(teensy), failsafes_(failsafes), timer_([this] { step(); }) {}

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
    if (Result r = vehicle_.drive(MotorValues{}, client); !r.ok()) {
        done(r);
        return;
    }
    client_ = client;
    done_ = std::move(done);
    findings_ = {};
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
    if (vehicle_.controller_client() != client_)
        return {Status::Busy, "another command took over the thrusters (or the caller left)"};
    if (!failsafes_.active().empty())
        return {Status::FailsafeActive, "a failsafe is active"};
    if (!teensy_.telemetry().online)
        return {Status::LinkError, "the Teensy went offline"};
    return {};
}

void DirectionDetection::end(Result r) {
    const bool ours = vehicle_.may_drive() && vehicle_.controller_client() == client_;
    phase_ = Phase::Idle;
    timer_.arm(DeadlineTimer::kNever);
    if (ours)
        (void)vehicle_.drive(MotorValues{}, client_);
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
    const auto& o = teensy_.telemetry().orientation;
    samples_.push_back({now, {o[0], o[1], o[2]}});
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
    if (Result r = vehicle_.drive(MotorValues{}, client_); !r.ok()) {
        end(r);
        return;
    }
    std::erase_if(samples_, [&](const Sample& s) { return s.t_ns + window < now; });
    // A vertical thruster's pulse (this run's or whatever moved the vehicle before it) leaves
    // pitch and roll swinging back (the vehicle is bottom-heavy); the window is judged only after
    // a rest of two windows.
    if (now - phase_start_ns_ >= 3 * window) {
        // Still: the mean attitude of the window's second half is within detect_settle_mrad of
        // its first half's on every axis (a spread test would be fooled by the sensor's noise).
        const uint64_t half = window / 2;
        const std::array<double, 3> first = mean_from(samples_, 0);
        const std::array<double, 3> second = mean_from(samples_, now - half);
        std::array<double, 3> moved{};
        double worst = 0.0;
        for (std::size_t k = 0; k < 3; ++k) {
            moved[k] = k == 0 ? wrap(second[k] - first[k]) : second[k] - first[k];
            worst = std::max(worst, std::abs(moved[k]));
        }
        if (worst <= c.detect_settle_mrad / 1000.0) {
            // The whole window's mean: the sensor's noise averaged over every sample. A slow drift
            // is left in (0.5 mrad/s moves ~1 mrad by the measurement, a tenth of the threshold).
            baseline_ = mean_from(samples_, 0);
            samples_.clear();
            phase_ = Phase::Pulse;
            phase_start_ns_ = now;
            if (Result r = vehicle_.drive(pulse_values(), client_); !r.ok())
                end(r);
            return;
        }
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
        if (Result r = vehicle_.drive(pulse_values(), client_); !r.ok())
            end(r);
        return;
    }
    if (Result r = vehicle_.drive(MotorValues{}, client_); !r.ok()) {
        end(r);
        return;
    }
    const std::array<double, 3> after = mean_from(samples_, phase_start_ns_ + uint64_t(double(length) * kMeasureFrom));
    DirectionFinding& f = findings_[motor_];
    f.change = {wrap(after[0] - baseline_[0]), after[1] - baseline_[1], after[2] - baseline_[2]};
    f.judgement = judge_direction(config_.mixing, motor_, c.detect_pulse_value, f.change, c.detect_threshold_mrad / 1000.0);
    log_notice("direction detection: thruster %zu %s (yaw %+.4f pitch %+.4f roll %+.4f rad, margin %.1f)", motor_,
               std::string(verdict_name(f.judgement.verdict)).c_str(), f.change[0], f.change[1], f.change[2],
               f.judgement.margin);
    samples_.clear();
    if (++motor_ >= kMotorCount) {
        end({});
        return;
    }
    phase_ = Phase::Settle;
    phase_start_ns_ = now;
}

std::string DirectionDetection::fragment() const {
    std::array<DirectionJudgement, kMotorCount> j{};
    for (std::size_t i = 0; i < kMotorCount; ++i)
        j[i] = findings_[i].judgement;
    return reversal_fragment(config_.thrusters, j);
}

} // namespace caracara
