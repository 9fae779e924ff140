// Teensy SPI link: codec vectors worked by hand, reply classification, the retry decision,
// the Confirm handshake, and SpiDev / TeensyLink over an in-process fake of the device seam.
#include "drivers/platform/spi_dev.hpp"
#include "drivers/protocol/teensy_codec.hpp"
#include "drivers/devices/teensy_link.hpp"

#include <algorithm>
#include "tests/catch.hpp"
#include <cerrno>
#include <fcntl.h>
#include <cmath>
#include <functional>
#include <limits>
#include <linux/spi/spidev.h>
#include <memory>
#include <string>
#include <vector>

using namespace caracara;
using namespace caracara::teensy;

namespace {

using Bytes = std::vector<uint8_t>;

Bytes bytes_of(const Frame& f) { return Bytes(f.span().begin(), f.span().end()); }

Frame frame_ok(const TeensyResult<Frame>& r) {
    REQUIRE(r.ok());
    return r.value;
}

// The bytes a Teensy would clock back for `sent`: don't-care 0xA5 under command and data,
// then `answer` in the answer slot and `ack` in the ack slot.
Bytes teensy_reply(const Frame& sent, uint8_t ack, const Bytes& answer = {}) {
    Bytes rx(sent.size, 0xA5);
    REQUIRE(answer.size() == sent.answer_len);
    for (size_t i = 0; i < answer.size(); ++i)
        rx[sent.answer_offset() + i] = answer[i];
    rx[sent.ack_offset()] = ack;
    return rx;
}

constexpr double kPi = 3.14159265358979323846;

} // namespace

// ---------------------------------------------------------------------------------------------
// Command table and frame layout
// ---------------------------------------------------------------------------------------------

TEST_CASE("teensy command table matches the seed plus the 0x09 extension") {
    struct Row {
        uint8_t id, data, answer;
        const char* name;
    };
    const Row rows[] = {
        {0x01, 0, 1, "confirm"},      {0x02, 2, 0, "set-speed"},    {0x03, 4, 0, "turn"},
        {0x04, 4, 0, "turn-to"},      {0x05, 1, 0, "stop"},         {0x06, 2, 0, "servo"},
        {0x07, 1, 2, "get-distance"}, {0x08, 1, 4, "get-orientation"}, {0x09, 3, 0, "set-leds"},
    };
    for (const Row& row : rows) {
        const CommandInfo* c = find_command(row.id);
        REQUIRE(c != nullptr);
        CHECK(static_cast<uint8_t>(c->id) == row.id);
        CHECK(c->data_len == row.data);
        CHECK(c->answer_len == row.answer);
        CHECK(c->name == row.name);
        CHECK(&command_info(c->id) == c);
    }
    CHECK(find_command(0x00) == nullptr);
    CHECK(find_command(0x0A) == nullptr); // reserved for future extensions
    CHECK(find_command(0xFF) == nullptr); // 0xFF is "busy" in the ack slot, never a command
    // Turn is relative: the only command a lost ack makes unsafe to resend.
    CHECK_FALSE(command_info(Command::Turn).idempotent);
    CHECK(command_info(Command::TurnTo).idempotent);
    // Longest frame: Get orientation = 1 + 1 + 4 + 1 = 7 <= 10 = 1 + 4 + 4 + 1.
    CHECK(kMaxFrame == 10);
    STATIC_REQUIRE(kMaxFrame <= SpiDev::kMaxPerByteTransfers);
}

TEST_CASE("teensy Confirm encodes the host value in the answer slot") {
    // [01][value][ack=00]: no data, 1 answer byte, so 1 + 0 + 1 + 1 = 3 bytes.
    Frame poll = frame_ok(encode_confirm(kConfirmPoll));
    CHECK(bytes_of(poll) == Bytes{0x01, 0x00, 0x00});
    CHECK(poll.answer_offset() == 1);
    CHECK(poll.ack_offset() == 2);
    Frame ack = frame_ok(encode_confirm(kConfirmAck));
    CHECK(bytes_of(ack) == Bytes{0x01, 0x01, 0x00});
}

TEST_CASE("teensy Set Speed encodes two's complement int8 and rejects wider ints") {
    // 100 = 0x64; -100 = 256 - 100 = 156 = 0x9C. Frame [02][L][R][ack] = 4 bytes.
    CHECK(bytes_of(frame_ok(encode_set_speed(100, -100))) == Bytes{0x02, 0x64, 0x9C, 0x00});
    // Extremes: -128 = 0x80, 127 = 0x7F; -1 = 0xFF; 0 = 0x00.
    CHECK(bytes_of(frame_ok(encode_set_speed(-128, 127))) == Bytes{0x02, 0x80, 0x7F, 0x00});
    CHECK(bytes_of(frame_ok(encode_set_speed(-1, 0))) == Bytes{0x02, 0xFF, 0x00, 0x00});
    CHECK(encode_set_speed(128, 0).error == TeensyError::SpeedOutOfRange);
    CHECK(encode_set_speed(0, -129).error == TeensyError::SpeedOutOfRange);
    CHECK(encode_set_speed(255, 0).error == TeensyError::SpeedOutOfRange); // would wrap to -1
    CHECK(encode_set_speed(std::numeric_limits<int>::min(), 0).error == TeensyError::SpeedOutOfRange);
}

TEST_CASE("teensy Turn and Turn to encode float32 little-endian") {
    // 1.5 = 1.1b x 2^0: sign 0, exponent 127 = 0x7F, fraction .1b = 0x400000
    //   -> 0 01111111 10000000000000000000000 = 0x3FC00000 -> LE 00 00 C0 3F.
    CHECK(bytes_of(frame_ok(encode_turn(1.5))) == Bytes{0x03, 0x00, 0x00, 0xC0, 0x3F, 0x00});
    // pi/2 = 1.5707963... x 2^0: exponent 127; fraction 0.5707963 x 2^23 = 4788186.63 -> 4788187
    //   = 0x490FDB -> 0x3F800000 | 0x490FDB = 0x3FC90FDB; negative sets bit 31 -> 0xBFC90FDB
    //   -> LE DB 0F C9 BF.
    CHECK(bytes_of(frame_ok(encode_turn(-kPi / 2))) == Bytes{0x03, 0xDB, 0x0F, 0xC9, 0xBF, 0x00});
    // pi = (pi/2) x 2^1: same fraction, exponent 128 -> 0x40490FDB -> LE DB 0F 49 40.
    CHECK(bytes_of(frame_ok(encode_turn_to(kPi))) == Bytes{0x04, 0xDB, 0x0F, 0x49, 0x40, 0x00});
    // 0.0 is all zero bits.
    CHECK(bytes_of(frame_ok(encode_turn_to(0.0))) == Bytes{0x04, 0x00, 0x00, 0x00, 0x00, 0x00});
}

TEST_CASE("teensy Turn rejects NaN, infinities and values beyond float32") {
    for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                       -std::numeric_limits<double>::infinity(), 1e39, -1e39}) {
        CHECK(encode_turn(bad).error == TeensyError::AngleNotFinite);
        CHECK(encode_turn_to(bad).error == TeensyError::AngleNotFinite);
    }
    // FLT_MAX itself is finite on the wire: 0x7F7FFFFF -> LE FF FF 7F 7F.
    CHECK(bytes_of(frame_ok(encode_turn(static_cast<double>(std::numeric_limits<float>::max())))) ==
          Bytes{0x03, 0xFF, 0xFF, 0x7F, 0x7F, 0x00});
}

TEST_CASE("teensy Stop encodes the brake duty as uint8") {
    // [05][duty][ack]: 255 = 0xFF full brake, 0 = coast.
    CHECK(bytes_of(frame_ok(encode_stop(255))) == Bytes{0x05, 0xFF, 0x00});
    CHECK(bytes_of(frame_ok(encode_stop(0))) == Bytes{0x05, 0x00, 0x00});
    CHECK(bytes_of(frame_ok(encode_stop(128))) == Bytes{0x05, 0x80, 0x00});
    CHECK(encode_stop(-1).error == TeensyError::DutyOutOfRange);
    CHECK(encode_stop(256).error == TeensyError::DutyOutOfRange);
}

TEST_CASE("teensy Servo encodes id and degrees and validates both") {
    // 90 = 0x5A, 180 = 0xB4. Frame [06][id][deg][ack].
    CHECK(bytes_of(frame_ok(encode_servo(2, 90))) == Bytes{0x06, 0x02, 0x5A, 0x00});
    CHECK(bytes_of(frame_ok(encode_servo(3, 180))) == Bytes{0x06, 0x03, 0xB4, 0x00});
    CHECK(bytes_of(frame_ok(encode_servo(0, 0))) == Bytes{0x06, 0x00, 0x00, 0x00});
    // Default: 4 servos, ids 0..3.
    CHECK(encode_servo(4, 90).error == TeensyError::ServoIdOutOfRange);
    CHECK(encode_servo(-1, 90).error == TeensyError::ServoIdOutOfRange);
    CHECK(encode_servo(0, 181).error == TeensyError::ServoAngleOutOfRange);
    CHECK(encode_servo(0, -1).error == TeensyError::ServoAngleOutOfRange);
    // The id is checked first: both wrong reports the id.
    CHECK(encode_servo(9, 999).error == TeensyError::ServoIdOutOfRange);
    TeensyLimits six{6, 4};
    CHECK(bytes_of(frame_ok(encode_servo(5, 45, six))) == Bytes{0x06, 0x05, 0x2D, 0x00});
    CHECK(encode_servo(6, 45, six).error == TeensyError::ServoIdOutOfRange);
    // A configured count beyond what a uint8 id can address stops at 255.
    TeensyLimits many{1000, 1000};
    CHECK(encode_servo(255, 1, many).ok());
    CHECK(encode_servo(256, 1, many).error == TeensyError::ServoIdOutOfRange);
    TeensyLimits none{0, 0};
    CHECK(encode_servo(0, 1, none).error == TeensyError::ServoIdOutOfRange);
}

TEST_CASE("teensy Get distance encodes the sensor id and decodes uint16 LE millimetres") {
    // [07][id][ans lo][ans hi][ack] = 5 bytes; host sends zeros in the answer and ack slots.
    Frame f = frame_ok(encode_get_distance(1));
    CHECK(bytes_of(f) == Bytes{0x07, 0x01, 0x00, 0x00, 0x00});
    CHECK(f.answer_offset() == 2);
    CHECK(f.ack_offset() == 4);
    // 1500 mm = 0x05DC -> LE DC 05.
    Reply r = decode_reply(f, teensy_reply(f, 0x07, {0xDC, 0x05}));
    CHECK(r.status == FrameStatus::Ok);
    TeensyResult<uint16_t> d = decode_distance(r);
    REQUIRE(d.ok());
    CHECK(d.value == 1500);
    // 0xFF in the answer is data: 0xFFFF = 65535 mm, not "busy".
    d = decode_distance(decode_reply(f, teensy_reply(f, 0x07, {0xFF, 0xFF})));
    REQUIRE(d.ok());
    CHECK(d.value == 65535);
    CHECK(encode_get_distance(4).error == TeensyError::SensorIdOutOfRange);
    CHECK(encode_get_distance(-1).error == TeensyError::SensorIdOutOfRange);
    CHECK(encode_get_distance(7, TeensyLimits{4, 8}).ok());
}

TEST_CASE("teensy Get orientation encodes the axis and decodes float32 LE radians") {
    // [08][axis][a0 a1 a2 a3][ack] = 7 bytes.
    Frame f = frame_ok(encode_get_orientation(static_cast<int>(Axis::Yaw)));
    CHECK(bytes_of(f) == Bytes{0x08, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00});
    CHECK(bytes_of(frame_ok(encode_get_orientation(1))) == Bytes{0x08, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00});
    CHECK(bytes_of(frame_ok(encode_get_orientation(2))) == Bytes{0x08, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00});
    CHECK(encode_get_orientation(3).error == TeensyError::AxisOutOfRange);
    CHECK(encode_get_orientation(-1).error == TeensyError::AxisOutOfRange);
    // 0.25 = 1.0b x 2^-2: exponent 127 - 2 = 125 = 0x7D -> 0 01111101 0...0 = 0x3E800000
    //   -> LE 00 00 80 3E.
    TeensyResult<float> v = decode_orientation(decode_reply(f, teensy_reply(f, 0x08, {0x00, 0x00, 0x80, 0x3E})));
    REQUIRE(v.ok());
    CHECK(v.value == 0.25f);
    // -1.0 = sign 1, exponent 127 -> 0xBF800000 -> LE 00 00 80 BF.
    v = decode_orientation(decode_reply(f, teensy_reply(f, 0x08, {0x00, 0x00, 0x80, 0xBF})));
    REQUIRE(v.ok());
    CHECK(v.value == -1.0f);
    // pi/2 as above: LE DB 0F C9 3F.
    v = decode_orientation(decode_reply(f, teensy_reply(f, 0x08, {0xDB, 0x0F, 0xC9, 0x3F})));
    REQUIRE(v.ok());
    CHECK(v.value == static_cast<float>(kPi / 2));
    // A quiet NaN (0x7FC00000, LE 00 00 C0 7F) or +inf (0x7F800000) is acked but not a value.
    CHECK(decode_orientation(decode_reply(f, teensy_reply(f, 0x08, {0x00, 0x00, 0xC0, 0x7F}))).error ==
          TeensyError::BadAnswer);
    CHECK(decode_orientation(decode_reply(f, teensy_reply(f, 0x08, {0x00, 0x00, 0x80, 0x7F}))).error ==
          TeensyError::BadAnswer);
}

TEST_CASE("teensy Set LEDs (extension 0x09) encodes r, g, b") {
    // [09][r][g][b][ack]: 128 = 0x80.
    CHECK(bytes_of(frame_ok(encode_set_leds(255, 128, 0))) == Bytes{0x09, 0xFF, 0x80, 0x00, 0x00});
    CHECK(encode_set_leds(256, 0, 0).error == TeensyError::LedValueOutOfRange);
    CHECK(encode_set_leds(0, -1, 0).error == TeensyError::LedValueOutOfRange);
    CHECK(encode_set_leds(0, 0, 300).error == TeensyError::LedValueOutOfRange);
}

TEST_CASE("teensy little-endian helpers") {
    uint8_t b[4] = {};
    put_u16_le(b, 0x1234);
    CHECK((b[0] == 0x34 && b[1] == 0x12));
    CHECK(get_u16_le(b) == 0x1234);
    put_f32_le(b, 1.5f);
    CHECK((b[0] == 0x00 && b[1] == 0x00 && b[2] == 0xC0 && b[3] == 0x3F));
    CHECK(get_f32_le(b) == 1.5f);
}

TEST_CASE("teensy error names are distinct and kebab-case") {
    CHECK(teensy_error_name(TeensyError::Busy) == "busy");
    CHECK(teensy_error_name(TeensyError::BusyExhausted) == "busy-exhausted");
    CHECK(teensy_error_name(TeensyError::LinkError) == "link-error");
    CHECK(teensy_error_name(TeensyError::ConfirmTimeout) == "confirm-timeout");
    std::vector<std::string_view> seen;
    for (int e = 0; e <= static_cast<int>(TeensyError::ConfirmAckFailed); ++e) {
        std::string_view n = teensy_error_name(static_cast<TeensyError>(e));
        CHECK(n != "unknown");
        CHECK(std::find(seen.begin(), seen.end(), n) == seen.end());
        seen.push_back(n);
    }
}

// ---------------------------------------------------------------------------------------------
// Reply classification: only the ack slot decides
// ---------------------------------------------------------------------------------------------

TEST_CASE("teensy ack equal to the command is ok, 0xFF is busy, anything else is a link error") {
    Frame f = frame_ok(encode_set_speed(10, 10)); // [02 0A 0A 00]
    Reply r = decode_reply(f, Bytes{0x00, 0x00, 0x00, 0x02});
    CHECK(r.status == FrameStatus::Ok);
    CHECK(r.ack == 0x02);
    CHECK(decode_ack(r) == TeensyError::None);

    r = decode_reply(f, Bytes{0x00, 0x00, 0x00, 0xFF});
    CHECK(r.status == FrameStatus::Busy);
    CHECK(decode_ack(r) == TeensyError::Busy);

    for (uint8_t garbage : {uint8_t{0x00}, uint8_t{0x01}, uint8_t{0x03}, uint8_t{0x42}, uint8_t{0xFE}}) {
        r = decode_reply(f, Bytes{0x00, 0x00, 0x00, garbage});
        CHECK(r.status == FrameStatus::LinkError);
        CHECK(r.ack == garbage);
        CHECK(decode_ack(r) == TeensyError::LinkError);
    }
    // A torn reply (wrong length) has no ack slot to trust.
    CHECK(decode_reply(f, Bytes{0x00, 0x00, 0x02}).status == FrameStatus::LinkError);
    CHECK(decode_reply(f, Bytes{0x00, 0x00, 0x00, 0x02, 0x02}).status == FrameStatus::LinkError);
}

TEST_CASE("teensy 0xFF in Confirm's answer slot is 'finished', 0xFF in the ack slot is 'busy'") {
    Frame poll = frame_ok(encode_confirm(kConfirmPoll)); // [01 00 00]
    // rx [xx][answer=FF][ack=01]: acked, task finished.
    Reply r = decode_reply(poll, Bytes{0x00, 0xFF, 0x01});
    REQUIRE(r.status == FrameStatus::Ok);
    TeensyResult<uint8_t> c = decode_confirm(r);
    REQUIRE(c.ok());
    CHECK(c.value == kConfirmFinished);
    // rx [xx][answer=00][ack=01]: acked, still running.
    c = decode_confirm(decode_reply(poll, Bytes{0x00, 0x00, 0x01}));
    REQUIRE(c.ok());
    CHECK(c.value == 0x00);
    // rx [xx][answer=00][ack=FF]: busy; the answer slot means nothing.
    CHECK(decode_confirm(decode_reply(poll, Bytes{0x00, 0x00, 0xFF})).error == TeensyError::Busy);
    // rx [xx][answer=FF][ack=FF]: still busy, not finished.
    CHECK(decode_confirm(decode_reply(poll, Bytes{0x00, 0xFF, 0xFF})).error == TeensyError::Busy);
    // A MISO stuck high reads all 0xFF: busy (bounded by the retries), never "finished".
    CHECK(decode_reply(poll, Bytes{0xFF, 0xFF, 0xFF}).status == FrameStatus::Busy);
    // rx [xx][answer=FF][ack=00]: garbage ack, the "finished" byte is not believed.
    CHECK(decode_confirm(decode_reply(poll, Bytes{0x00, 0xFF, 0x00})).error == TeensyError::LinkError);
}

TEST_CASE("teensy typed decoders refuse a reply of another command") {
    Frame poll = frame_ok(encode_confirm(0));
    Reply r = decode_reply(poll, Bytes{0x00, 0x12, 0x01});
    REQUIRE(r.status == FrameStatus::Ok);
    CHECK(decode_distance(r).error == TeensyError::LinkError);
    CHECK(decode_orientation(r).error == TeensyError::LinkError);
    Frame dist = frame_ok(encode_get_distance(0));
    CHECK(decode_confirm(decode_reply(dist, Bytes{0, 0, 1, 2, 0x07})).error == TeensyError::LinkError);
    // Busy and link error pass through the typed decoders.
    CHECK(decode_distance(decode_reply(dist, Bytes{0, 0, 0, 0, 0xFF})).error == TeensyError::Busy);
    CHECK(decode_distance(decode_reply(dist, Bytes{0, 0, 0, 0, 0x08})).error == TeensyError::LinkError);
}

// ---------------------------------------------------------------------------------------------
// Retry decision
// ---------------------------------------------------------------------------------------------

TEST_CASE("teensy retry: busy resends after the delay, bounded by max_busy_retries") {
    RetryPolicy p; // 10 retries
    RetryTracker t(p, command_info(Command::GetOrientation));
    for (int i = 0; i < 10; ++i) {
        RetryDecision d = t.on_reply(FrameStatus::Busy);
        CHECK(d.action == RetryAction::ResendAfterDelay);
        CHECK(d.error == TeensyError::Busy);
    }
    CHECK(t.busy_retries() == 10);
    // The 11th busy reply (1 first try + 10 resends) gives up.
    RetryDecision d = t.on_reply(FrameStatus::Busy);
    CHECK(d.action == RetryAction::Fail);
    CHECK(d.error == TeensyError::BusyExhausted);

    RetryTracker t2(p, command_info(Command::GetOrientation));
    CHECK(t2.on_reply(FrameStatus::Busy).action == RetryAction::ResendAfterDelay);
    CHECK(t2.on_reply(FrameStatus::Ok).action == RetryAction::Done);

    RetryPolicy none;
    none.max_busy_retries = 0;
    RetryTracker t3(none, command_info(Command::Stop));
    CHECK(t3.on_reply(FrameStatus::Busy).error == TeensyError::BusyExhausted);
}

TEST_CASE("teensy retry: a link error is resent once for idempotent commands, never for Turn") {
    RetryPolicy p;
    RetryTracker t(p, command_info(Command::SetSpeed));
    RetryDecision d = t.on_reply(FrameStatus::LinkError);
    CHECK(d.action == RetryAction::ResendAfterDelay);
    CHECK(d.error == TeensyError::LinkError);
    d = t.on_reply(FrameStatus::LinkError);
    CHECK(d.action == RetryAction::Fail);
    CHECK(d.error == TeensyError::LinkError);
    CHECK(t.link_retries() == 1);

    RetryTracker turn(p, command_info(Command::Turn));
    d = turn.on_reply(FrameStatus::LinkError);
    CHECK(d.action == RetryAction::Fail);
    CHECK(d.error == TeensyError::LinkError);
    // Busy is safe to resend even for Turn: a busy Teensy has not acted on the frame.
    RetryTracker turn2(p, command_info(Command::Turn));
    CHECK(turn2.on_reply(FrameStatus::Busy).action == RetryAction::ResendAfterDelay);

    RetryPolicy off;
    off.retry_link_error_once = false;
    RetryTracker t2(off, command_info(Command::Stop));
    CHECK(t2.on_reply(FrameStatus::LinkError).action == RetryAction::Fail);
}

// ---------------------------------------------------------------------------------------------
// Confirm handshake
// ---------------------------------------------------------------------------------------------

namespace {
constexpr uint64_t kMs = 1'000'000;
ConfirmHandshakeConfig hs_config() {
    ConfirmHandshakeConfig c;
    c.poll_interval_ns = 10 * kMs;
    c.timeout_ns = 100 * kMs;
    c.ack_attempts = 2;
    return c;
}
TeensyResult<uint8_t> answer(uint8_t v) { return {TeensyError::None, v}; }
TeensyResult<uint8_t> failed(TeensyError e) { return {e, 0}; }
} // namespace

TEST_CASE("teensy handshake polls Confirm(0) until 0xFF, then acknowledges with Confirm(1)") {
    ConfirmHandshake h(hs_config());
    CHECK(h.next(0).action == ConfirmHandshake::Action::Idle);
    const uint64_t t0 = 1000 * kMs;
    h.start(t0);
    CHECK(h.state() == ConfirmHandshake::State::Polling);

    // First poll goes out at once.
    ConfirmHandshake::Step s = h.next(t0);
    REQUIRE(s.action == ConfirmHandshake::Action::Send);
    CHECK(bytes_of(s.frame) == Bytes{0x01, 0x00, 0x00});
    h.on_result(answer(0x00), t0 + 1 * kMs); // still turning

    // Not before the poll interval has passed since the reply.
    s = h.next(t0 + 5 * kMs);
    CHECK(s.action == ConfirmHandshake::Action::Wait);
    CHECK(s.at_ns == t0 + 11 * kMs);
    s = h.next(t0 + 11 * kMs);
    REQUIRE(s.action == ConfirmHandshake::Action::Send);
    CHECK(bytes_of(s.frame) == Bytes{0x01, 0x00, 0x00});
    h.on_result(answer(kConfirmFinished), t0 + 12 * kMs);
    CHECK(h.state() == ConfirmHandshake::State::Acknowledging);
    CHECK(h.polls() == 2);

    // The acknowledgement goes out at once, with a positive value in the answer slot.
    s = h.next(t0 + 12 * kMs);
    REQUIRE(s.action == ConfirmHandshake::Action::Send);
    CHECK(bytes_of(s.frame) == Bytes{0x01, 0x01, 0x00});
    h.on_result(answer(0x00), t0 + 13 * kMs);
    CHECK(h.state() == ConfirmHandshake::State::Done);
    CHECK(h.next(t0 + 14 * kMs).action == ConfirmHandshake::Action::Done);
    CHECK(h.error() == TeensyError::None);
}

TEST_CASE("teensy handshake times out when the task never reports finished") {
    ConfirmHandshake h(hs_config());
    h.start(0);
    uint64_t now = 0;
    int sends = 0;
    for (;;) {
        ConfirmHandshake::Step s = h.next(now);
        if (s.action == ConfirmHandshake::Action::Send) {
            ++sends;
            h.on_result(answer(0x00), now);
        } else if (s.action == ConfirmHandshake::Action::Wait) {
            CHECK(s.at_ns > now);
            now = s.at_ns;
        } else {
            CHECK(s.action == ConfirmHandshake::Action::Failed);
            CHECK(s.error == TeensyError::ConfirmTimeout);
            break;
        }
    }
    // Polls at 0, 10, ..., 90 ms; at 100 ms the deadline has passed.
    CHECK(sends == 10);
    CHECK(now == 100 * kMs);
    CHECK(h.state() == ConfirmHandshake::State::Failed);
    CHECK(h.error() == TeensyError::ConfirmTimeout);
}

TEST_CASE("teensy handshake wakes the caller at the deadline, not after it") {
    ConfirmHandshakeConfig c = hs_config();
    c.poll_interval_ns = 70 * kMs;
    ConfirmHandshake h(c);
    h.start(0);
    REQUIRE(h.next(0).action == ConfirmHandshake::Action::Send);
    h.on_result(answer(0), 50 * kMs);
    ConfirmHandshake::Step s = h.next(50 * kMs);
    CHECK(s.action == ConfirmHandshake::Action::Wait);
    CHECK(s.at_ns == 100 * kMs); // min(50 + 70, deadline 100)
    CHECK(h.next(100 * kMs).error == TeensyError::ConfirmTimeout);
}

TEST_CASE("teensy handshake keeps polling through link failures until the deadline") {
    ConfirmHandshake h(hs_config());
    h.start(0);
    REQUIRE(h.next(0).action == ConfirmHandshake::Action::Send);
    h.on_result(failed(TeensyError::BusyExhausted), 0);
    CHECK(h.state() == ConfirmHandshake::State::Polling);
    CHECK(h.last_link_error() == TeensyError::BusyExhausted);
    REQUIRE(h.next(10 * kMs).action == ConfirmHandshake::Action::Send);
    h.on_result(answer(0xFF), 10 * kMs);
    CHECK(h.state() == ConfirmHandshake::State::Acknowledging);
}

TEST_CASE("teensy handshake: other answer values are 'not finished', a late finish is still acked") {
    ConfirmHandshake h(hs_config());
    h.start(0);
    REQUIRE(h.next(0).action == ConfirmHandshake::Action::Send);
    h.on_result(answer(0x7F), 0); // reserved value: keep polling
    CHECK(h.state() == ConfirmHandshake::State::Polling);
    REQUIRE(h.next(95 * kMs).action == ConfirmHandshake::Action::Send);
    // The reply to the last poll lands after the deadline: the task did finish.
    h.on_result(answer(0xFF), 105 * kMs);
    CHECK(h.state() == ConfirmHandshake::State::Acknowledging);
    ConfirmHandshake::Step s = h.next(105 * kMs);
    REQUIRE(s.action == ConfirmHandshake::Action::Send);
    CHECK(bytes_of(s.frame) == Bytes{0x01, 0x01, 0x00});
}

TEST_CASE("teensy handshake: the acknowledgement is retried, then fails with its own error") {
    ConfirmHandshake h(hs_config()); // ack_attempts = 2
    h.start(0);
    REQUIRE(h.next(0).action == ConfirmHandshake::Action::Send);
    h.on_result(answer(0xFF), 0);
    REQUIRE(h.next(0).action == ConfirmHandshake::Action::Send);
    h.on_result(failed(TeensyError::LinkError), 1 * kMs);
    CHECK(h.state() == ConfirmHandshake::State::Acknowledging);
    ConfirmHandshake::Step s = h.next(2 * kMs);
    CHECK(s.action == ConfirmHandshake::Action::Wait);
    CHECK(s.at_ns == 11 * kMs);
    s = h.next(11 * kMs);
    REQUIRE(s.action == ConfirmHandshake::Action::Send);
    CHECK(bytes_of(s.frame) == Bytes{0x01, 0x01, 0x00});
    h.on_result(failed(TeensyError::Io), 11 * kMs);
    s = h.next(12 * kMs);
    CHECK(s.action == ConfirmHandshake::Action::Failed);
    CHECK(s.error == TeensyError::ConfirmAckFailed);
    CHECK(h.last_link_error() == TeensyError::Io);
}

TEST_CASE("teensy handshake ignores results it did not ask for, and restarts cleanly") {
    ConfirmHandshake h(hs_config());
    h.on_result(answer(0xFF), 0); // idle: ignored
    CHECK(h.state() == ConfirmHandshake::State::Idle);
    h.start(0);
    h.on_result(answer(0xFF), 0); // no Send outstanding: ignored
    CHECK(h.state() == ConfirmHandshake::State::Polling);
    CHECK(h.polls() == 0);
    REQUIRE(h.next(0).action == ConfirmHandshake::Action::Send);
    h.on_result(answer(0xFF), 0);
    REQUIRE(h.next(0).action == ConfirmHandshake::Action::Send);
    h.on_result(answer(0), 0);
    REQUIRE(h.state() == ConfirmHandshake::State::Done);
    h.start(500 * kMs);
    CHECK(h.state() == ConfirmHandshake::State::Polling);
    CHECK(h.polls() == 0);
    CHECK(h.next(500 * kMs).action == ConfirmHandshake::Action::Send);
}

// The spidev driver and the frame engine over a real SPI path are tested against the
// simulated Teensy in tests/integration/test_teensy_link_on_sim.cpp, not against a scripted stand-in.
