#include "drivers/protocol/teensy_codec.hpp"

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

Status status_of(TeensyError e) {
    using E = TeensyError;
    switch (e) {
    case E::None: return Status::Ok;
    case E::SpeedOutOfRange:
    case E::DutyOutOfRange:
    case E::ServoIdOutOfRange:
    case E::ServoAngleOutOfRange:
    case E::SensorIdOutOfRange:
    case E::AxisOutOfRange:
    case E::LedValueOutOfRange: return Status::OutOfRange;
    case E::AngleNotFinite: return Status::InvalidValue;
    case E::Busy:
    case E::BusyExhausted: return Status::Busy;
    case E::ConfirmTimeout: return Status::Timeout;
    case E::LinkError:
    case E::BadAnswer:
    case E::Io:
    case E::ConfirmAckFailed: return Status::LinkError;
    }
    return Status::LinkError;
}

Result result_of(TeensyError e, std::string_view what) {
    if (e == TeensyError::None)
        return {};
    return {status_of(e), std::string(what) + ": " + std::string(teensy_error_name(e))};
}

} // namespace caracara::teensy
