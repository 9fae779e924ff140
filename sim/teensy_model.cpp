#include "sim/teensy_model.hpp"

#include <bit>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace caracara::sim {

namespace {

struct CommandShape {
    bool known;
    std::size_t data;
    std::size_t answer;
};

CommandShape shape_of(uint8_t cmd) {
    switch (cmd) {
    case teensy::kConfirm: return {true, 0, 1};
    case teensy::kSetSpeed: return {true, 2, 0};
    case teensy::kTurn: return {true, 4, 0};
    case teensy::kTurnTo: return {true, 4, 0};
    case teensy::kStop: return {true, 1, 0};
    case teensy::kServo: return {true, 2, 0};
    case teensy::kGetDistance: return {true, 1, 2};
    case teensy::kGetOrientation: return {true, 1, 4};
    case teensy::kSetLeds: return {true, 3, 0};
    default: return {false, 0, 0};
    }
}

float f32_le(const std::array<uint8_t, 4>& d) {
    uint32_t u = static_cast<uint32_t>(d[0]) | (static_cast<uint32_t>(d[1]) << 8) |
                 (static_cast<uint32_t>(d[2]) << 16) | (static_cast<uint32_t>(d[3]) << 24);
    return std::bit_cast<float>(u);
}

void put_f32_le(std::array<uint8_t, 4>& out, float v) {
    uint32_t u = std::bit_cast<uint32_t>(v);
    for (std::size_t i = 0; i < 4; ++i)
        out[i] = static_cast<uint8_t>(u >> (8 * i));
}

// An unknown command has no known length; keep the log bounded whatever the host sends.
constexpr std::size_t kMaxLoggedUnknownBytes = 64;

} // namespace

std::string_view teensy_command_name(uint8_t command) {
    const auto& table = EnumNames<TeensyCommand>::table;
    if (command < static_cast<uint8_t>(table.front().value) || command > static_cast<uint8_t>(table.back().value))
        return "Unknown";
    return name_of(static_cast<TeensyCommand>(command));
}

TeensyModel::TeensyModel(TeensyConfig cfg, AttitudeSource attitude)
    : cfg_(cfg), attitude_(std::move(attitude)), frames_(cfg.log_capacity), noise_rng_(cfg.noise_seed) {
    if (!attitude_)
        throw std::invalid_argument("TeensyModel needs an attitude source");
    if (!std::isfinite(cfg_.orientation_noise_rad) || cfg_.orientation_noise_rad < 0.0 ||
        !std::isfinite(cfg_.yaw_drift_rad_s))
        throw std::invalid_argument("TeensyModel noise must be finite and non-negative, drift finite");
    noise_ = std::normal_distribution<double>(0.0, cfg_.orientation_noise_rad > 0.0 ? cfg_.orientation_noise_rad : 1.0);
    if (!std::isfinite(cfg_.wheel_k) || !std::isfinite(cfg_.front_circumference) ||
        !std::isfinite(cfg_.back_circumference) || cfg_.front_circumference <= 0.0 ||
        cfg_.back_circumference <= 0.0)
        throw std::invalid_argument("TeensyModel wheel parameters must be finite, circumferences positive");
    if (!std::isfinite(cfg_.turn_rate_rad_s) || cfg_.turn_rate_rad_s <= 0.0)
        throw std::invalid_argument("TeensyModel turn rate must be positive");
    // Ids travel as uint8.
    if (cfg_.servo_count > 256 || cfg_.distance_sensor_count > 256)
        throw std::invalid_argument("TeensyModel supports at most 256 servos and distance sensors");
    if (cfg_.servo_initial_degrees > teensy::kMaxServoDegrees)
        throw std::invalid_argument("TeensyModel initial servo angle must be 0..180");
    if (cfg_.log_capacity == 0)
        throw std::invalid_argument("TeensyModel log capacity must be at least 1");
    servos_.assign(cfg_.servo_count, cfg_.servo_initial_degrees);
    distances_.assign(cfg_.distance_sensor_count, cfg_.distance_initial_mm);
}

TeensyModel::TeensyModel(TeensyConfig cfg, const VehicleBody& body)
    : TeensyModel(cfg, [b = &body] { return b->attitude(); }) {}

void TeensyModel::transfer(std::span<const uint8_t> tx, std::span<uint8_t> rx, const SpiTransferParams& p,
                           uint64_t now_ns) {
    // Speed, delays and cs_change are the bus model's business; the bus calls end_message
    // whenever chip select is released.
    (void)p;
    for (std::size_t i = 0; i < tx.size(); ++i) {
        uint8_t out = on_byte(tx[i], now_ns);
        if (i < rx.size())
            rx[i] = out;
    }
}

void TeensyModel::end_message(uint64_t now_ns) {
    if (!f_.active)
        return;
    log_frame(f_.known ? TeensyFrameOutcome::Incomplete : TeensyFrameOutcome::Unknown, now_ns);
    f_ = Frame{};
}

uint8_t TeensyModel::on_byte(uint8_t in, uint64_t now_ns) {
    if (!f_.active) {
        // Command slot: the slave has nothing loaded yet and shifts out zero.
        begin_frame(in, now_ns);
        return 0;
    }
    if (!f_.known) {
        if (f_.mosi.size() < kMaxLoggedUnknownBytes) {
            f_.mosi.push_back(in);
            f_.miso.push_back(0);
        }
        return 0;
    }
    const std::size_t pos = f_.pos;
    const uint8_t out = slot_output();
    f_.mosi.push_back(in);
    f_.miso.push_back(out);
    if (pos <= f_.data_len) {
        f_.data[pos - 1] = in;
        if (pos == f_.data_len)
            prepare_answer();
    } else if (pos == f_.data_len + 1 && f_.answer_len > 0) {
        f_.host_answer0 = in;
    }
    ++f_.pos;
    if (pos == f_.data_len + f_.answer_len + 1)
        finish_frame(now_ns);
    return out;
}

void TeensyModel::begin_frame(uint8_t cmd, uint64_t now_ns) {
    const CommandShape s = shape_of(cmd);
    f_ = Frame{};
    f_.active = true;
    f_.known = s.known;
    f_.cmd = cmd;
    f_.data_len = s.data;
    f_.answer_len = s.answer;
    f_.pos = 1;
    f_.start_ns = now_ns;
    f_.mosi.push_back(cmd);
    f_.miso.push_back(0);
    frames_.received(cmd);
    if (!s.known)
        return;
    f_.plan = faults_.next();
    // With no data bytes (Confirm) the answer must be loaded right after the command byte.
    if (f_.data_len == 0)
        prepare_answer();
}

void TeensyModel::prepare_answer() {
    // A busy or deaf slave has nothing to answer and does not look at the arguments.
    if (f_.plan == Plan::Busy || f_.plan == Plan::NoAnswer)
        return;
    const auto& d = f_.data;
    switch (f_.cmd) {
    case teensy::kConfirm:
        f_.answer[0] = task_ == TeensyTaskState::FinishedAwaitingAck ? teensy::kTaskFinished : 0;
        break;
    case teensy::kTurn:
    case teensy::kTurnTo:
        f_.invalid = !std::isfinite(f32_le(d));
        break;
    case teensy::kServo:
        f_.invalid = d[0] >= servos_.size() || d[1] > teensy::kMaxServoDegrees;
        break;
    case teensy::kGetDistance:
        if (d[0] >= distances_.size()) {
            f_.invalid = true;
        } else {
            const uint16_t mm = distances_[d[0]];
            f_.answer[0] = static_cast<uint8_t>(mm & 0xFF);
            f_.answer[1] = static_cast<uint8_t>(mm >> 8);
        }
        break;
    case teensy::kGetOrientation: {
        if (d[0] > 2) {
            f_.invalid = true;
            break;
        }
        const BodyAttitude a = measured_orientation();
        const double v = d[0] == 0 ? a.yaw : d[0] == 1 ? a.pitch : a.roll;
        put_f32_le(f_.answer, static_cast<float>(v));
        break;
    }
    default: break; // commands without answers or argument constraints
    }
}

uint8_t TeensyModel::slot_output() const {
    const std::size_t pos = f_.pos;
    if (f_.plan == Plan::NoAnswer || pos <= f_.data_len)
        return 0;
    if (pos <= f_.data_len + f_.answer_len)
        return f_.plan == Plan::Busy ? 0 : f_.answer[pos - f_.data_len - 1];
    return ack_byte();
}

uint8_t TeensyModel::ack_byte() const {
    switch (f_.plan) {
    case Plan::Busy: return teensy::kAckBusy;
    case Plan::NoAnswer: return teensy::kAckNone;
    case Plan::Garbage: return static_cast<uint8_t>(f_.cmd ^ teensy::kGarbageXor);
    case Plan::Normal: break;
    }
    return f_.invalid ? teensy::kAckNone : f_.cmd;
}

void TeensyModel::finish_frame(uint64_t now_ns) {
    TeensyFrameOutcome o = TeensyFrameOutcome::Ok;
    switch (f_.plan) {
    case Plan::Busy: o = TeensyFrameOutcome::Busy; break;
    case Plan::NoAnswer: o = TeensyFrameOutcome::NoAnswer; break;
    case Plan::Garbage:
        o = TeensyFrameOutcome::GarbageAck;
        if (!f_.invalid)
            execute();
        break;
    case Plan::Normal:
        if (f_.invalid) {
            o = TeensyFrameOutcome::Invalid;
        } else {
            execute();
        }
        break;
    }
    log_frame(o, now_ns);
    f_ = Frame{};
}

void TeensyModel::execute() {
    const auto& d = f_.data;
    switch (f_.cmd) {
    case teensy::kConfirm:
        // Only an acknowledgement of a "finished" answer this very frame carried counts.
        if (f_.host_answer0 != 0 && f_.answer[0] == teensy::kTaskFinished &&
            task_ == TeensyTaskState::FinishedAwaitingAck) {
            task_ = TeensyTaskState::Idle;
            ++acks_;
        }
        break;
    case teensy::kSetSpeed: {
        // Seed: v1 = front right, v2 = front left, v3 = back left (+), v4 = back right (-).
        const double v2 = static_cast<int8_t>(d[0]);
        const double v1 = static_cast<int8_t>(d[1]);
        const double g = cfg_.wheel_k * cfg_.front_circumference / cfg_.back_circumference;
        wheels_.front_left = v2;
        wheels_.front_right = v1;
        wheels_.back_left = g * ((v1 + v2) / 2.0 + (v2 - v1));
        wheels_.back_right = g * ((v1 + v2) / 2.0 - (v2 - v1));
        break;
    }
    case teensy::kTurn: {
        const float a = f32_le(d);
        last_turn_ = a;
        remaining_ = a;
        target_heading_ = VehicleBody::wrap_angle(heading() + a);
        task_ = remaining_ == 0.0 ? TeensyTaskState::FinishedAwaitingAck : TeensyTaskState::Running;
        break;
    }
    case teensy::kTurnTo: {
        const float h = f32_le(d);
        last_turn_to_ = h;
        target_heading_ = VehicleBody::wrap_angle(h);
        remaining_ = VehicleBody::wrap_angle(target_heading_ - heading());
        task_ = remaining_ == 0.0 ? TeensyTaskState::FinishedAwaitingAck : TeensyTaskState::Running;
        break;
    }
    case teensy::kStop:
        stop_duty_ = d[0];
        wheels_ = {};
        if (task_ == TeensyTaskState::Running) {
            remaining_ = 0.0;
            task_ = TeensyTaskState::FinishedAwaitingAck;
        }
        break;
    case teensy::kServo: servos_[d[0]] = d[1]; break;
    case teensy::kSetLeds: leds_ = {d[0], d[1], d[2]}; break;
    default: break; // the getters' work was done when the answer was loaded
    }
    frames_.executed(f_.cmd);
}

void TeensyModel::log_frame(TeensyFrameOutcome o, uint64_t now_ns) {
    TeensyFrameRecord r;
    r.start_ns = f_.start_ns;
    r.end_ns = now_ns;
    r.command = f_.cmd;
    r.name = teensy_command_name(f_.cmd);
    r.outcome = o;
    r.mosi = std::move(f_.mosi);
    r.miso = std::move(f_.miso);
    frames_.add(std::move(r));
}

void TeensyModel::step(double dt_s, uint64_t now_ns) {
    (void)now_ns;
    if (std::isfinite(dt_s) && dt_s > 0.0)
        drift_ = VehicleBody::wrap_angle(drift_ + cfg_.yaw_drift_rad_s * dt_s);
    if (task_ != TeensyTaskState::Running || !std::isfinite(dt_s) || dt_s <= 0.0)
        return;
    const double d = cfg_.turn_rate_rad_s * dt_s;
    if (d >= std::abs(remaining_)) {
        heading_offset_ = VehicleBody::wrap_angle(heading_offset_ + remaining_);
        remaining_ = 0.0;
        task_ = TeensyTaskState::FinishedAwaitingAck;
    } else {
        const double move = std::copysign(d, remaining_);
        heading_offset_ = VehicleBody::wrap_angle(heading_offset_ + move);
        remaining_ -= move;
    }
}

bool TeensyModel::set_distance_mm(std::size_t sensor, uint16_t mm) {
    if (sensor >= distances_.size())
        return false;
    distances_[sensor] = mm;
    return true;
}

double TeensyModel::heading() const { return VehicleBody::wrap_angle(attitude_().yaw + heading_offset_); }

BodyAttitude TeensyModel::orientation() const {
    if (replayed_)
        return *replayed_;
    BodyAttitude a = attitude_();
    a.yaw = VehicleBody::wrap_angle(a.yaw + heading_offset_ + drift_);
    return a;
}

BodyAttitude TeensyModel::measured_orientation() {
    BodyAttitude a = orientation();
    if (replayed_ || cfg_.orientation_noise_rad <= 0.0)
        return a;
    a.yaw = VehicleBody::wrap_angle(a.yaw + noise_(noise_rng_));
    a.pitch = VehicleBody::wrap_angle(a.pitch + noise_(noise_rng_));
    a.roll = VehicleBody::wrap_angle(a.roll + noise_(noise_rng_));
    return a;
}

} // namespace caracara::sim
