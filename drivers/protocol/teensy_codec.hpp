// The Raspberry Pi <-> Teensy SPI protocol ("Raspberry Pi - Teensy SPI protocol" documentation, with the byte
// order, busy/retry policy and the 0x09 extension defined in docs/teensy-protocol.md).
// Pure logic: frame encoding with input validation, reply classification and decoding, the
// (the busy/link-error retry decision and the Confirm handshake are in retry_tracker.hpp and
// confirm_handshake.hpp). No system calls, no clock.
#pragma once

#include "core/enum_names.hpp"
#include "core/link_config.hpp"
#include "core/status.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace caracara::teensy {

enum class Command : uint8_t {
    Confirm = 0x01,
    SetSpeed = 0x02,
    Turn = 0x03,
    TurnTo = 0x04,
    Stop = 0x05,
    Servo = 0x06,
    GetDistance = 0x07,
    GetOrientation = 0x08,
    SetLeds = 0x09, // vehicle extension
};

struct CommandInfo {
    Command id;
    uint8_t data_len;   // bytes the host sends after the command byte
    uint8_t answer_len; // bytes the Teensy answers after the data
    // Sending it twice has the same effect as once, so a frame whose reply was garbled may be
    // resent. Turn is relative: resending it after a lost ack could turn twice.
    bool idempotent;
    std::string_view name;
};

inline constexpr std::array<CommandInfo, 9> kCommands{{
    {Command::Confirm, 0, 1, true, "confirm"},
    {Command::SetSpeed, 2, 0, true, "set-speed"},
    {Command::Turn, 4, 0, false, "turn"},
    {Command::TurnTo, 4, 0, true, "turn-to"},
    {Command::Stop, 1, 0, true, "stop"},
    {Command::Servo, 2, 0, true, "servo"},
    {Command::GetDistance, 1, 2, true, "get-distance"},
    {Command::GetOrientation, 1, 4, true, "get-orientation"},
    {Command::SetLeds, 3, 0, true, "set-leds"},
}};

// nullptr for an id not in the table (0x00, 0x0A and up are not defined).
const CommandInfo* find_command(uint8_t id);
const CommandInfo& command_info(Command c);

inline constexpr size_t kMaxData = 4;
inline constexpr size_t kMaxAnswer = 4;
inline constexpr size_t kMaxFrame = 1 + kMaxData + kMaxAnswer + 1;
inline constexpr uint8_t kAckBusy = 0xFF;          // in the ACK slot: busy, resend the frame
inline constexpr uint8_t kConfirmFinished = 0xFF;  // in Confirm's ANSWER slot: task finished
inline constexpr uint8_t kConfirmPoll = 0;         // host value in Confirm: "finished yet?"
inline constexpr uint8_t kConfirmAck = 1;          // host value in Confirm: "seen, thank you"
inline constexpr uint8_t kFirstReservedCommand = 0x0A; // future vehicle extensions

enum class Axis : uint8_t { Yaw = 0, Pitch = 1, Roll = 2 };

enum class TeensyError : uint8_t {
    None = 0,
    // Input validation: nothing was sent.
    SpeedOutOfRange,      // Set Speed value outside int8 -128..127
    AngleNotFinite,       // Turn / Turn to angle is NaN, infinite or beyond float32 range
    DutyOutOfRange,       // Stop duty outside uint8 0..255
    ServoIdOutOfRange,    // servo id outside 0..servo_count-1
    ServoAngleOutOfRange, // servo angle outside 0..180 degrees
    SensorIdOutOfRange,   // distance sensor id outside 0..distance_sensor_count-1
    AxisOutOfRange,       // orientation axis outside 0..2
    LedValueOutOfRange,   // LED colour component outside uint8 0..255
    // Link: the frame was sent.
    Busy,                 // one reply had 0xFF in the ack slot (the link retries these)
    BusyExhausted,        // still busy after the configured retries
    LinkError,            // the ack slot was neither the command nor 0xFF
    BadAnswer,            // acked, but the answer is not a value (orientation NaN/Inf)
    Io,                   // the SPI transfer itself failed (errno kept by the link)
    // Confirm handshake.
    ConfirmTimeout,       // the task did not report finished before the deadline
    ConfirmAckFailed,     // finished, but the acknowledgement could not be delivered
};

} // namespace caracara::teensy
namespace caracara {
template <>
struct EnumNames<teensy::TeensyError> {
    static constexpr std::array<EnumName<teensy::TeensyError>, 16> table{{
        {teensy::TeensyError::None, "none"},
        {teensy::TeensyError::SpeedOutOfRange, "speed-out-of-range"},
        {teensy::TeensyError::AngleNotFinite, "angle-not-finite"},
        {teensy::TeensyError::DutyOutOfRange, "duty-out-of-range"},
        {teensy::TeensyError::ServoIdOutOfRange, "servo-id-out-of-range"},
        {teensy::TeensyError::ServoAngleOutOfRange, "servo-angle-out-of-range"},
        {teensy::TeensyError::SensorIdOutOfRange, "sensor-id-out-of-range"},
        {teensy::TeensyError::AxisOutOfRange, "axis-out-of-range"},
        {teensy::TeensyError::LedValueOutOfRange, "led-value-out-of-range"},
        {teensy::TeensyError::Busy, "busy"},
        {teensy::TeensyError::BusyExhausted, "busy-exhausted"},
        {teensy::TeensyError::LinkError, "link-error"},
        {teensy::TeensyError::BadAnswer, "bad-answer"},
        {teensy::TeensyError::Io, "io"},
        {teensy::TeensyError::ConfirmTimeout, "confirm-timeout"},
        {teensy::TeensyError::ConfirmAckFailed, "confirm-ack-failed"},
    }};
};
} // namespace caracara
namespace caracara::teensy {
inline std::string_view teensy_error_name(TeensyError v) { return name_of(v); }
// The Status a caller gets for it (core/status.cpp names it).
Status status_of(TeensyError e);
// The Result a caller gets for a frame (`what`) that ended in `e`: its status, "<what>: <error>".
Result result_of(TeensyError e, std::string_view what);

// A value or the reason there is none. (std::expected is C++23.)
template <typename T>
struct TeensyResult {
    TeensyError error = TeensyError::None;
    T value{};
    bool ok() const { return error == TeensyError::None; }
};

// One frame as the host clocks it out: [command][data][answer slot][ack slot]. The answer
// and ack slots are zeros, except Confirm's answer slot, which carries the host's value.
struct Frame {
    std::array<uint8_t, kMaxFrame> bytes{};
    uint8_t size = 0;
    uint8_t data_len = 0;
    uint8_t answer_len = 0;

    uint8_t command() const { return bytes[0]; }
    std::span<const uint8_t> span() const { return {bytes.data(), size}; }
    size_t answer_offset() const { return 1u + data_len; }
    size_t ack_offset() const { return size - 1u; }
};

inline constexpr int kServoMaxDegrees = 180;

// Encoders validate first and return the error without a frame when the input is bad.
// Wider argument types than the wire's let callers pass untrusted input (D-Bus ints and
// doubles) straight through and get a named error instead of a silent wrap.
TeensyResult<Frame> encode_confirm(uint8_t value);
TeensyResult<Frame> encode_set_speed(int left, int right);
TeensyResult<Frame> encode_turn(double radians);
TeensyResult<Frame> encode_turn_to(double heading_radians);
TeensyResult<Frame> encode_stop(int brake_duty);
TeensyResult<Frame> encode_servo(int servo_id, int degrees, const TeensyLimits& limits = {});
TeensyResult<Frame> encode_get_distance(int sensor_id, const TeensyLimits& limits = {});
TeensyResult<Frame> encode_get_orientation(int axis);
TeensyResult<Frame> encode_set_leds(int red, int green, int blue);

enum class FrameStatus : uint8_t {
    Ok,        // ack slot == command
    Busy,      // ack slot == 0xFF: the Teensy did not act on the frame; resend it
    LinkError, // anything else (including a reply of the wrong length)
};

struct Reply {
    FrameStatus status = FrameStatus::LinkError;
    uint8_t command = 0;
    uint8_t ack = 0;
    uint8_t answer_len = 0;
    std::array<uint8_t, kMaxAnswer> answer{}; // only meaningful when status is Ok
};

// Classifies the bytes clocked in while `sent` was clocked out. Only the ack slot decides;
// a 0xFF in the answer slot (Confirm's "finished") is data, never "busy".
Reply decode_reply(const Frame& sent, std::span<const uint8_t> received);

// Typed answers. Each fails with Busy / LinkError for a reply that was not Ok, and with
// LinkError when the reply belongs to another command.
TeensyResult<uint8_t> decode_confirm(const Reply& r);
TeensyResult<uint16_t> decode_distance(const Reply& r);   // millimetres, little-endian
TeensyResult<float> decode_orientation(const Reply& r);   // radians, float32 LE; NaN/Inf -> BadAnswer
TeensyError decode_ack(const Reply& r);                   // commands without an answer

// Little-endian helpers, exposed for the simulator's Teensy and for tests.
void put_u16_le(uint8_t* out, uint16_t v);
void put_f32_le(uint8_t* out, float v);
uint16_t get_u16_le(const uint8_t* in);
float get_f32_le(const uint8_t* in);

} // namespace caracara::teensy
