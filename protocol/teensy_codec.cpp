#include "protocol/teensy_codec.hpp"

#include <algorithm>
#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>

namespace caracara::teensy {

static_assert(sizeof(float) == 4 && std::numeric_limits<float>::is_iec559, "float32 must be IEEE-754");

const CommandInfo* find_command(uint8_t id) {
    for (const CommandInfo& c : kCommands)
        if (static_cast<uint8_t>(c.id) == id)
            return &c;
    return nullptr;
}

const CommandInfo& command_info(Command c) {
    // The table is indexed by id - 1; the static_asserts keep that true.
    return kCommands[static_cast<uint8_t>(c) - 1u];
}
static_assert(kCommands[0].id == Command::Confirm && kCommands[8].id == Command::SetLeds);
static_assert(static_cast<uint8_t>(kCommands[8].id) + 1 == kFirstReservedCommand);

std::string_view teensy_error_name(TeensyError e) {
    switch (e) {
    case TeensyError::None: return "none";
    case TeensyError::SpeedOutOfRange: return "speed-out-of-range";
    case TeensyError::AngleNotFinite: return "angle-not-finite";
    case TeensyError::DutyOutOfRange: return "duty-out-of-range";
    case TeensyError::ServoIdOutOfRange: return "servo-id-out-of-range";
    case TeensyError::ServoAngleOutOfRange: return "servo-angle-out-of-range";
    case TeensyError::SensorIdOutOfRange: return "sensor-id-out-of-range";
    case TeensyError::AxisOutOfRange: return "axis-out-of-range";
    case TeensyError::LedValueOutOfRange: return "led-value-out-of-range";
    case TeensyError::Busy: return "busy";
    case TeensyError::BusyExhausted: return "busy-exhausted";
    case TeensyError::LinkError: return "link-error";
    case TeensyError::BadAnswer: return "bad-answer";
    case TeensyError::Io: return "io";
    case TeensyError::ConfirmTimeout: return "confirm-timeout";
    case TeensyError::ConfirmAckFailed: return "confirm-ack-failed";
    }
    return "unknown";
}

void put_u16_le(uint8_t* out, uint16_t v) {
    out[0] = static_cast<uint8_t>(v & 0xFFu);
    out[1] = static_cast<uint8_t>(v >> 8);
}

void put_f32_le(uint8_t* out, float v) {
    const auto bits = std::bit_cast<uint32_t>(v);
    for (int i = 0; i < 4; ++i)
        out[i] = static_cast<uint8_t>((bits >> (8 * i)) & 0xFFu);
}

uint16_t get_u16_le(const uint8_t* in) {
    return static_cast<uint16_t>(in[0] | (in[1] << 8));
}

float get_f32_le(const uint8_t* in) {
    uint32_t bits = 0;
    for (int i = 0; i < 4; ++i)
        bits |= static_cast<uint32_t>(in[i]) << (8 * i);
    return std::bit_cast<float>(bits);
}

namespace {

TeensyResult<Frame> fail(TeensyError e) { return {e, {}}; }

// The answer and ack slots stay zero: the host has nothing to say there.
TeensyResult<Frame> make_frame(Command c, std::initializer_list<uint8_t> data) {
    const CommandInfo& info = command_info(c);
    Frame f;
    f.data_len = info.data_len;
    f.answer_len = info.answer_len;
    f.size = static_cast<uint8_t>(1 + info.data_len + info.answer_len + 1);
    f.bytes[0] = static_cast<uint8_t>(c);
    std::copy(data.begin(), data.end(), f.bytes.begin() + 1);
    return {TeensyError::None, f};
}

bool in_range(int v, int lo, int hi) { return v >= lo && v <= hi; }

TeensyResult<Frame> encode_angle(Command c, double radians) {
    // Beyond FLT_MAX the float32 on the wire would be infinite.
    if (!std::isfinite(radians) || std::fabs(radians) > static_cast<double>(FLT_MAX))
        return fail(TeensyError::AngleNotFinite);
    uint8_t b[4];
    put_f32_le(b, static_cast<float>(radians));
    return make_frame(c, {b[0], b[1], b[2], b[3]});
}

} // namespace

TeensyResult<Frame> encode_confirm(uint8_t value) {
    // Confirm has no data; the host's value rides in the answer slot (0 = poll, >0 = ack).
    TeensyResult<Frame> r = make_frame(Command::Confirm, {});
    r.value.bytes[r.value.answer_offset()] = value;
    return r;
}

TeensyResult<Frame> encode_set_speed(int left, int right) {
    if (!in_range(left, INT8_MIN, INT8_MAX) || !in_range(right, INT8_MIN, INT8_MAX))
        return fail(TeensyError::SpeedOutOfRange);
    // Two's complement int8: -1 -> 0xFF, -128 -> 0x80.
    return make_frame(Command::SetSpeed, {static_cast<uint8_t>(left & 0xFF), static_cast<uint8_t>(right & 0xFF)});
}

TeensyResult<Frame> encode_turn(double radians) { return encode_angle(Command::Turn, radians); }

TeensyResult<Frame> encode_turn_to(double heading_radians) { return encode_angle(Command::TurnTo, heading_radians); }

TeensyResult<Frame> encode_stop(int brake_duty) {
    if (!in_range(brake_duty, 0, UINT8_MAX))
        return fail(TeensyError::DutyOutOfRange);
    return make_frame(Command::Stop, {static_cast<uint8_t>(brake_duty)});
}

TeensyResult<Frame> encode_servo(int servo_id, int degrees, const TeensyLimits& limits) {
    if (!in_range(servo_id, 0, std::min(limits.servo_count - 1, int{UINT8_MAX})))
        return fail(TeensyError::ServoIdOutOfRange);
    if (!in_range(degrees, 0, kServoMaxDegrees))
        return fail(TeensyError::ServoAngleOutOfRange);
    return make_frame(Command::Servo, {static_cast<uint8_t>(servo_id), static_cast<uint8_t>(degrees)});
}

TeensyResult<Frame> encode_get_distance(int sensor_id, const TeensyLimits& limits) {
    if (!in_range(sensor_id, 0, std::min(limits.distance_sensor_count - 1, int{UINT8_MAX})))
        return fail(TeensyError::SensorIdOutOfRange);
    return make_frame(Command::GetDistance, {static_cast<uint8_t>(sensor_id)});
}

TeensyResult<Frame> encode_get_orientation(int axis) {
    if (!in_range(axis, static_cast<int>(Axis::Yaw), static_cast<int>(Axis::Roll)))
        return fail(TeensyError::AxisOutOfRange);
    return make_frame(Command::GetOrientation, {static_cast<uint8_t>(axis)});
}

TeensyResult<Frame> encode_set_leds(int red, int green, int blue) {
    if (!in_range(red, 0, UINT8_MAX) || !in_range(green, 0, UINT8_MAX) || !in_range(blue, 0, UINT8_MAX))
        return fail(TeensyError::LedValueOutOfRange);
    return make_frame(Command::SetLeds,
                      {static_cast<uint8_t>(red), static_cast<uint8_t>(green), static_cast<uint8_t>(blue)});
}

Reply decode_reply(const Frame& sent, std::span<const uint8_t> received) {
    Reply r;
    r.command = sent.command();
    r.answer_len = sent.answer_len;
    if (sent.size < 2 || received.size() != sent.size)
        return r; // LinkError: a torn frame has no trustworthy ack slot
    r.ack = received[sent.ack_offset()];
    if (r.ack == r.command) {
        r.status = FrameStatus::Ok;
        std::copy_n(received.begin() + static_cast<std::ptrdiff_t>(sent.answer_offset()), sent.answer_len,
                    r.answer.begin());
    } else if (r.ack == kAckBusy) {
        r.status = FrameStatus::Busy;
    } else {
        r.status = FrameStatus::LinkError;
    }
    return r;
}

namespace {

TeensyError reply_error(const Reply& r, Command expected) {
    if (r.command != static_cast<uint8_t>(expected) || r.answer_len != command_info(expected).answer_len)
        return TeensyError::LinkError;
    switch (r.status) {
    case FrameStatus::Ok: return TeensyError::None;
    case FrameStatus::Busy: return TeensyError::Busy;
    case FrameStatus::LinkError: return TeensyError::LinkError;
    }
    return TeensyError::LinkError;
}

} // namespace

TeensyResult<uint8_t> decode_confirm(const Reply& r) {
    if (TeensyError e = reply_error(r, Command::Confirm); e != TeensyError::None)
        return {e, 0};
    return {TeensyError::None, r.answer[0]};
}

TeensyResult<uint16_t> decode_distance(const Reply& r) {
    if (TeensyError e = reply_error(r, Command::GetDistance); e != TeensyError::None)
        return {e, 0};
    return {TeensyError::None, get_u16_le(r.answer.data())};
}

TeensyResult<float> decode_orientation(const Reply& r) {
    if (TeensyError e = reply_error(r, Command::GetOrientation); e != TeensyError::None)
        return {e, 0.0f};
    const float v = get_f32_le(r.answer.data());
    if (!std::isfinite(v))
        return {TeensyError::BadAnswer, 0.0f};
    return {TeensyError::None, v};
}

TeensyError decode_ack(const Reply& r) {
    switch (r.status) {
    case FrameStatus::Ok: return TeensyError::None;
    case FrameStatus::Busy: return TeensyError::Busy;
    case FrameStatus::LinkError: return TeensyError::LinkError;
    }
    return TeensyError::LinkError;
}

RetryDecision RetryTracker::on_reply(FrameStatus status) {
    switch (status) {
    case FrameStatus::Ok:
        return {RetryAction::Done, TeensyError::None};
    case FrameStatus::Busy:
        if (busy_retries_ < policy_.max_busy_retries) {
            ++busy_retries_;
            return {RetryAction::ResendAfterDelay, TeensyError::Busy};
        }
        return {RetryAction::Fail, TeensyError::BusyExhausted};
    case FrameStatus::LinkError:
        if (policy_.retry_link_error_once && command_.idempotent && link_retries_ == 0) {
            ++link_retries_;
            return {RetryAction::ResendAfterDelay, TeensyError::LinkError};
        }
        return {RetryAction::Fail, TeensyError::LinkError};
    }
    return {RetryAction::Fail, TeensyError::LinkError};
}

void ConfirmHandshake::start(uint64_t now_ns) {
    state_ = State::Polling;
    error_ = TeensyError::None;
    last_link_error_ = TeensyError::None;
    // Saturate: a huge timeout means "practically never", not a wrapped deadline in the past.
    deadline_ns_ = config_.timeout_ns > UINT64_MAX - now_ns ? UINT64_MAX : now_ns + config_.timeout_ns;
    next_send_ns_ = now_ns;
    polls_ = 0;
    acks_sent_ = 0;
    awaiting_ = false;
}

ConfirmHandshake::Step ConfirmHandshake::next(uint64_t now_ns) {
    Step s;
    switch (state_) {
    case State::Idle:
        s.action = Action::Idle;
        return s;
    case State::Done:
        s.action = Action::Done;
        return s;
    case State::Failed:
        s.action = Action::Failed;
        s.error = error_;
        return s;
    case State::Polling:
        if (now_ns >= deadline_ns_) {
            state_ = State::Failed;
            error_ = TeensyError::ConfirmTimeout;
            awaiting_ = false;
            s.action = Action::Failed;
            s.error = error_;
            return s;
        }
        if (now_ns < next_send_ns_) {
            s.action = Action::Wait;
            s.at_ns = std::min(next_send_ns_, deadline_ns_);
            return s;
        }
        s.action = Action::Send;
        s.frame = encode_confirm(kConfirmPoll).value;
        s.at_ns = now_ns;
        awaiting_ = true;
        return s;
    case State::Acknowledging:
        // No deadline here: the task has finished, and the attempts bound this phase.
        if (now_ns < next_send_ns_) {
            s.action = Action::Wait;
            s.at_ns = next_send_ns_;
            return s;
        }
        s.action = Action::Send;
        s.frame = encode_confirm(kConfirmAck).value;
        s.at_ns = now_ns;
        awaiting_ = true;
        return s;
    }
    return s;
}

void ConfirmHandshake::on_result(const TeensyResult<uint8_t>& result, uint64_t now_ns) {
    if (!awaiting_)
        return;
    awaiting_ = false;
    if (!result.ok())
        last_link_error_ = result.error;
    const uint64_t later = config_.poll_interval_ns > UINT64_MAX - now_ns ? UINT64_MAX
                                                                          : now_ns + config_.poll_interval_ns;
    if (state_ == State::Polling) {
        ++polls_;
        // Accepted even past the deadline: the answer is in, the task is finished.
        if (result.ok() && result.value == kConfirmFinished) {
            state_ = State::Acknowledging;
            next_send_ns_ = now_ns;
        } else {
            // 0 (still running), any other value (reserved) or a link failure: poll again.
            next_send_ns_ = later;
        }
    } else if (state_ == State::Acknowledging) {
        ++acks_sent_;
        if (result.ok()) {
            state_ = State::Done;
        } else if (acks_sent_ >= std::max(config_.ack_attempts, 1u)) {
            state_ = State::Failed;
            error_ = TeensyError::ConfirmAckFailed;
        } else {
            next_send_ns_ = later;
        }
    }
}

} // namespace caracara::teensy
