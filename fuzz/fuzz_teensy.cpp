// The Teensy SPI protocol: frame encoders, the reply and answer decoders, the busy/link-error
// retry engine (TeensyLink over SpiDev) and the Confirm handshake, with the Teensy played by
// the fuzz input (shadow_spi_bus.hpp). The expected results are worked out here from the
// protocol's rules (docs/teensy-protocol.md), not taken from the code under test.
//
// Input: [command][len][reply bytes]                                   the pure reply decoder
//        [flags][busy retries][servos][sensors]                        the link's configuration
//        then operations, [op] + its bytes, to the end (make_seeds.py writes this layout).
#include "drivers/devices/teensy_link.hpp"
#include "fuzz/byte_source.hpp"
#include "fuzz/check.hpp"
#include "fuzz/shadow_spi_bus.hpp"
#include "drivers/platform/spi_dev.hpp"
#include "drivers/protocol/confirm_handshake.hpp"
#include "drivers/protocol/teensy_codec.hpp"

#include <algorithm>
#include <bit>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <optional>
#include <vector>

using namespace caracara;
using namespace caracara::teensy;
using caracara::fuzz::ByteSource;
using caracara::fuzz::ShadowSpiBus;

namespace {

using Bytes = std::vector<uint8_t>;

// The frame layout of each command (seed table plus the 0x09 extension): data, answer bytes.
struct Shape {
    uint8_t data, answer;
};
constexpr Shape kShape[10] = {{0, 0}, {0, 1}, {2, 0}, {4, 0}, {4, 0}, {1, 0}, {2, 0}, {1, 2}, {1, 4}, {3, 0}};

Bytes frame_bytes(uint8_t cmd, std::initializer_list<uint8_t> data, uint8_t answer_slot0 = 0) {
    Bytes b{cmd};
    b.insert(b.end(), data);
    b.resize(1u + kShape[cmd].data + kShape[cmd].answer + 1u, 0);
    if (kShape[cmd].answer)
        b[1u + kShape[cmd].data] = answer_slot0;
    return b;
}

Bytes f32(float v) {
    const auto u = std::bit_cast<uint32_t>(v);
    return {uint8_t(u), uint8_t(u >> 8), uint8_t(u >> 16), uint8_t(u >> 24)};
}

Frame some_frame(uint8_t cmd, uint8_t x) {
    switch (cmd) {
    case 1: return encode_confirm(x).value;
    case 2: return encode_set_speed(int8_t(x), 0).value;
    case 3: return encode_turn(x).value;
    case 4: return encode_turn_to(-x).value;
    case 5: return encode_stop(x).value;
    case 6: return encode_servo(0, x % 181).value;
    case 7: return encode_get_distance(0).value;
    case 8: return encode_get_orientation(x % 3).value;
    default: return encode_set_leds(x, x, x).value;
    }
}

// decode_reply and the typed decoders against the rules: only the ack slot decides.
void check_reply(const Frame& f, std::span<const uint8_t> rx, const Reply& r) {
    const uint8_t cmd = f.command();
    FrameStatus want = FrameStatus::LinkError;
    if (rx.size() == f.size && f.size >= 2)
        want = rx.back() == cmd ? FrameStatus::Ok : rx.back() == 0xFF ? FrameStatus::Busy : FrameStatus::LinkError;
    FUZZ_CHECK(r.status == want && r.command == cmd, "reply to %#x classified %d, expected %d", cmd, int(r.status),
               int(want));
    const std::size_t off = 1u + kShape[cmd].data;
    if (want == FrameStatus::Ok)
        FUZZ_CHECK(std::equal(rx.begin() + long(off), rx.begin() + long(off + kShape[cmd].answer), r.answer.begin()),
                   "answer bytes not copied");
    const TeensyError status_error = want == FrameStatus::Ok     ? TeensyError::None
                                     : want == FrameStatus::Busy ? TeensyError::Busy
                                                                 : TeensyError::LinkError;
    FUZZ_CHECK(decode_ack(r) == status_error, "decode_ack wrong");
    const auto c = decode_confirm(r);
    const auto d = decode_distance(r);
    const auto o = decode_orientation(r);
    FUZZ_CHECK(c.error == (cmd == 1 ? status_error : TeensyError::LinkError), "confirm decoded for %#x", cmd);
    FUZZ_CHECK(d.error == (cmd == 7 ? status_error : TeensyError::LinkError), "distance decoded for %#x", cmd);
    if (cmd == 1 && c.ok())
        FUZZ_CHECK(c.value == rx[off], "confirm answer wrong");
    if (cmd == 7 && d.ok())
        FUZZ_CHECK(d.value == (rx[off] | rx[off + 1] << 8), "distance not little-endian");
    if (cmd != 8 || want != FrameStatus::Ok) {
        FUZZ_CHECK(o.error == (cmd == 8 ? status_error : TeensyError::LinkError), "orientation decoded for %#x", cmd);
    } else {
        uint32_t u = 0;
        for (int i = 0; i < 4; ++i)
            u |= uint32_t{rx[off + std::size_t(i)]} << (8 * i);
        const float v = std::bit_cast<float>(u);
        FUZZ_CHECK(std::isfinite(v) ? o.ok() && std::bit_cast<uint32_t>(o.value) == u
                                    : o.error == TeensyError::BadAnswer && o.value == 0.0f,
                   "orientation %#x decoded wrong", u);
    }
}

void pure_decoder(ByteSource& in) {
    const uint8_t sel = in.u8();
    const Frame f = some_frame(static_cast<uint8_t>(1 + sel % 9), static_cast<uint8_t>(sel >> 4));
    const auto rx = in.bytes(in.u8() % 12);
    check_reply(f, rx, decode_reply(f, rx));
}

// What TeensyLink must have done with the replies the shadow gave, by the retry rules:
// busy -> resend up to max_busy_retries times; link error -> resend once, idempotent commands
// only (every command but Turn); a failed transfer ends it.
struct Expected {
    TeensyError error = TeensyError::None;
    std::size_t frames = 0;
    Bytes last_rx;
};

Expected replay(const std::vector<ShadowSpiBus::Sent>& sent, std::size_t from, uint8_t cmd, const RetryPolicy& p) {
    Expected e;
    unsigned busy = 0, link = 0;
    for (std::size_t i = from; i < sent.size(); ++i) {
        const auto& s = sent[i];
        e.frames = i - from + 1;
        e.last_rx = s.rx;
        if (s.answer == ShadowSpiBus::Answer::Failed || s.answer == ShadowSpiBus::Answer::Short) {
            e.error = TeensyError::Io;
            return e;
        }
        const uint8_t ack = s.rx.back();
        if (ack == cmd) {
            e.error = TeensyError::None;
            return e;
        }
        if (ack == 0xFF) {
            if (busy++ < p.max_busy_retries)
                continue;
            e.error = TeensyError::BusyExhausted;
            return e;
        }
        if (p.retry_link_error_once && cmd != 0x03 && link++ == 0)
            continue;
        e.error = TeensyError::LinkError;
        return e;
    }
    e.error = TeensyError::Busy;  // the engine stopped before an outcome: never expected
    return e;
}

// Checks one TeensyLink call: validation first (nothing sent), then every frame on the wire is
// the expected one, and the outcome is what the replies dictate.
void check_call(ShadowSpiBus& spi, std::size_t before, const std::optional<Bytes>& frame, TeensyError validation,
                TeensyError got, const RetryPolicy& p, Bytes* last_rx = nullptr) {
    if (!frame) {
        FUZZ_CHECK(got == validation && spi.sent.size() == before, "refused call: %s, %zu frames sent",
                   std::string(teensy_error_name(got)).c_str(), spi.sent.size() - before);
        return;
    }
    for (std::size_t i = before; i < spi.sent.size(); ++i)
        FUZZ_CHECK(spi.sent[i].tx == *frame, "frame %zu of the call is not the encoded one", i - before);
    const Expected e = replay(spi.sent, before, (*frame)[0], p);
    FUZZ_CHECK(e.frames == spi.sent.size() - before, "%zu frames sent, the replies allowed %zu",
               spi.sent.size() - before, e.frames);
    if (got != TeensyError::BadAnswer)
        FUZZ_CHECK(got == e.error, "call to %#x: %s, expected %s", (*frame)[0], std::string(teensy_error_name(got)).c_str(),
                   std::string(teensy_error_name(e.error)).c_str());
    if (last_rx)
        *last_rx = e.last_rx;
}

bool in(int v, int lo, int hi) { return v >= lo && v <= hi; }

double some_angle(ByteSource& src) {
    const uint8_t how = src.u8();
    if (how & 1)
        return std::bit_cast<double>(src.u64());  // NaN, infinities, beyond float32
    return src.i16() / 1000.0;
}

void handshake(ByteSource& src, TeensyLink& link, ShadowSpiBus& spi) {
    ConfirmHandshakeConfig cfg;
    cfg.poll_interval_ns = src.u32();
    cfg.timeout_ns = src.u8() & 1 ? src.u64() : src.u32();
    cfg.ack_attempts = src.u8() % 6;
    uint64_t now = src.u8() & 1 ? src.u64() : src.u32();
    ConfirmHandshake h(cfg);
    FUZZ_CHECK(h.next(now).action == ConfirmHandshake::Action::Idle, "not idle before start");
    h.start(now);
    uint64_t deadline = now + cfg.timeout_ns < now ? UINT64_MAX : now + cfg.timeout_ns;
    uint64_t earliest = now;  // no frame before this
    unsigned sends = 0, acks = 0;
    bool finished = false;
    using A = ConfirmHandshake::Action;
    using S = ConfirmHandshake::State;
    for (int ev = 0; ev < 64 && !src.empty(); ++ev) {
        const uint8_t kind = src.u8();
        const S state = h.state();
        if (kind % 4 == 1) {  // time passes
            const uint64_t dt = src.u32();
            now = now + dt < now ? UINT64_MAX : now + dt;
            continue;
        }
        if (kind % 4 == 2) {  // an answer with no frame outstanding is ignored
            const unsigned polls = h.polls();
            h.on_result({static_cast<TeensyError>(src.u8() % 16), src.u8()}, now);
            FUZZ_CHECK(h.state() == state && h.polls() == polls, "a stray answer changed the handshake");
            continue;
        }
        if (kind % 4 == 3) {  // the owner starts a new Turn
            h.start(now);
            deadline = now + cfg.timeout_ns < now ? UINT64_MAX : now + cfg.timeout_ns;
            earliest = now;
            sends = acks = 0;
            finished = false;
            FUZZ_CHECK(h.state() == S::Polling && h.polls() == 0, "start did not reset");
            continue;
        }
        const ConfirmHandshake::Step s = h.next(now);
        if (state == S::Done || state == S::Failed) {
            FUZZ_CHECK(s.action == (state == S::Done ? A::Done : A::Failed) && s.error == h.error(),
                       "a finished handshake moved on");
            continue;
        }
        if (state == S::Polling && now >= deadline) {
            FUZZ_CHECK(s.action == A::Failed && s.error == TeensyError::ConfirmTimeout, "no timeout past the deadline");
            continue;
        }
        if (s.action == A::Wait) {
            FUZZ_CHECK(s.at_ns > now && now < earliest, "wait at %llu, now %llu", (unsigned long long)s.at_ns,
                       (unsigned long long)now);
            FUZZ_CHECK(state != S::Polling || s.at_ns <= deadline, "waits past the deadline");
            continue;
        }
        FUZZ_CHECK(s.action == A::Send && now >= earliest, "state %d: action %d", int(state), int(s.action));
        const Bytes want = frame_bytes(0x01, {}, state == S::Polling ? kConfirmPoll : kConfirmAck);
        FUZZ_CHECK(Bytes(s.frame.span().begin(), s.frame.span().end()) == want, "not the Confirm(%d) frame",
                   state == S::Polling ? 0 : 1);
        const std::size_t before = spi.sent.size();
        const auto r = link.execute(s.frame);
        Bytes rx;
        check_call(spi, before, want, TeensyError::None, r.error, link.config().retry, &rx);
        TeensyResult<uint8_t> res;
        if (r.ok())
            res = decode_confirm(r.value);
        else
            res.error = r.error;
        const uint64_t at = now + 1 < now ? now : now + 1;
        const unsigned polls = h.polls();
        ++sends;
        h.on_result(res, at);
        if (state == S::Polling) {
            FUZZ_CHECK(h.polls() == polls + 1, "poll not counted");
            if (res.ok() && res.value == kConfirmFinished) {
                finished = true;
                FUZZ_CHECK(h.state() == S::Acknowledging, "finished not acknowledged");
                earliest = at;
            } else {
                FUZZ_CHECK(h.state() == S::Polling, "left polling without a finished answer");
                earliest = at + cfg.poll_interval_ns < at ? UINT64_MAX : at + cfg.poll_interval_ns;
            }
        } else {
            ++acks;
            FUZZ_CHECK(finished, "acknowledging an unfinished task");
            if (res.ok())
                FUZZ_CHECK(h.state() == S::Done, "acked but not done");
            else if (acks >= std::max(cfg.ack_attempts, 1u))
                FUZZ_CHECK(h.state() == S::Failed && h.error() == TeensyError::ConfirmAckFailed, "ack attempts not bounded");
            else
                FUZZ_CHECK(h.state() == S::Acknowledging, "gave up before the attempts ran out");
            earliest = at + cfg.poll_interval_ns < at ? UINT64_MAX : at + cfg.poll_interval_ns;
        }
        FUZZ_CHECK(h.state() != S::Done || (finished && res.ok()), "done without a finished task and an ack");
    }
    (void)sends;
}

void link_calls(ByteSource& src) {
    const uint8_t flags = src.u8();
    SpiConfig spi_cfg;
    spi_cfg.byte_delay_us = flags & 1 ? static_cast<uint16_t>(1 + (flags >> 4)) : 0;
    TeensyLinkConfig cfg;
    cfg.retry.retry_link_error_once = (flags & 2) != 0;
    cfg.retry.busy_delay_us = 0;  // TeensyLink sleeps this long; the harness has no time to lose
    cfg.retry.max_busy_retries = src.u8() % 16;
    cfg.limits.servo_count = src.u8();
    cfg.limits.distance_sensor_count = src.u8();
    ShadowSpiBus spi_bus(src, spi_cfg);
    SpiDev spi(spi_bus, "/dev/spidev-fuzz", spi_cfg);
    FUZZ_CHECK(spi.open() == 0, "spidev open failed");
    TeensyLink link(spi, cfg);
    const RetryPolicy& p = cfg.retry;

    while (!src.empty()) {
        const uint8_t op = src.u8();
        const std::size_t before = spi_bus.sent.size();
        const uint64_t frames_before = link.counters().frames;
        switch (op % 10) {
        case 0: {
            const int l = src.i16() >> (op >> 4), r = src.i16() >> (op >> 4);
            const bool ok = in(l, -128, 127) && in(r, -128, 127);
            check_call(spi_bus, before,
                       ok ? std::optional(frame_bytes(2, {uint8_t(l), uint8_t(r)})) : std::nullopt,
                       TeensyError::SpeedOutOfRange, link.set_speed(l, r), p);
            break;
        }
        case 1:
        case 2: {
            const double a = some_angle(src);
            const bool ok = std::isfinite(a) && std::fabs(a) <= double(FLT_MAX);
            std::optional<Bytes> f;
            if (ok) {
                const Bytes b = f32(static_cast<float>(a));
                f = frame_bytes(op % 10 == 1 ? 3 : 4, {b[0], b[1], b[2], b[3]});
            }
            const TeensyError e = op % 10 == 1 ? link.turn(a) : link.turn_to(a);
            check_call(spi_bus, before, f, TeensyError::AngleNotFinite, e, p);
            break;
        }
        case 3: {
            const int d = src.i16() >> (op >> 4);
            check_call(spi_bus, before, in(d, 0, 255) ? std::optional(frame_bytes(5, {uint8_t(d)})) : std::nullopt,
                       TeensyError::DutyOutOfRange, link.stop(d), p);
            break;
        }
        case 4: {
            const int id = src.i16() >> (op >> 4), deg = src.i16() >> (op >> 4);
            const bool id_ok = in(id, 0, std::min(cfg.limits.servo_count - 1, 255));
            const bool ok = id_ok && in(deg, 0, 180);
            check_call(spi_bus, before, ok ? std::optional(frame_bytes(6, {uint8_t(id), uint8_t(deg)})) : std::nullopt,
                       id_ok ? TeensyError::ServoAngleOutOfRange : TeensyError::ServoIdOutOfRange,
                       link.servo(id, deg), p);
            break;
        }
        case 5: {
            const int id = src.i16() >> (op >> 4);
            const bool ok = in(id, 0, std::min(cfg.limits.distance_sensor_count - 1, 255));
            Bytes rx;
            const auto r = link.get_distance(id);
            check_call(spi_bus, before, ok ? std::optional(frame_bytes(7, {uint8_t(id)})) : std::nullopt,
                       TeensyError::SensorIdOutOfRange, r.error, p, &rx);
            if (ok && r.ok())
                FUZZ_CHECK(r.value == (rx[2] | rx[3] << 8), "distance is not the answer");
            break;
        }
        case 6: {
            const int axis = src.i16() >> (op >> 4);
            Bytes rx;
            const uint64_t bad_before = link.counters().bad_answers;
            const auto r = link.get_orientation(axis);
            check_call(spi_bus, before, in(axis, 0, 2) ? std::optional(frame_bytes(8, {uint8_t(axis)})) : std::nullopt,
                       TeensyError::AxisOutOfRange, r.error, p, &rx);
            if (r.error == TeensyError::BadAnswer || r.ok()) {
                const float v = std::bit_cast<float>(uint32_t(rx[2] | rx[3] << 8 | rx[4] << 16 | uint32_t(rx[5]) << 24));
                FUZZ_CHECK(std::isfinite(v) == r.ok() && (!r.ok() || std::bit_cast<uint32_t>(v) == std::bit_cast<uint32_t>(r.value)),
                           "orientation is not the answer");
                FUZZ_CHECK(link.counters().bad_answers == bad_before + (r.ok() ? 0 : 1), "bad answer not counted");
            }
            break;
        }
        case 7: {
            const int r = src.i16() >> (op >> 4), g = src.i16() >> (op >> 4), b = src.i16() >> (op >> 4);
            const bool ok = in(r, 0, 255) && in(g, 0, 255) && in(b, 0, 255);
            check_call(spi_bus, before,
                       ok ? std::optional(frame_bytes(9, {uint8_t(r), uint8_t(g), uint8_t(b)})) : std::nullopt,
                       TeensyError::LedValueOutOfRange, link.set_leds(r, g, b), p);
            break;
        }
        case 8: {
            const uint8_t v = src.u8();
            Bytes rx;
            const auto r = link.confirm(v);
            check_call(spi_bus, before, frame_bytes(1, {}, v), TeensyError::None, r.error, p, &rx);
            if (r.ok())
                FUZZ_CHECK(r.value == rx[1], "confirm answer wrong");
            break;
        }
        default:
            handshake(src, link, spi_bus);
            break;
        }
        FUZZ_CHECK(link.counters().frames - frames_before == spi_bus.sent.size() - before, "frames not counted");
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    ByteSource src(data, size);
    pure_decoder(src);
    link_calls(src);
    return 0;
}
