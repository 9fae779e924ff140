// The SeaBotix status decoder, both variants, and the order codec, first as pure functions on
// arbitrary bytes, then as the daemon uses them: ThrusterDriver and MuxTracker on one bus with
// up to four thrusters (same-address ones behind different PCA9544A channels), every transfer's
// outcome and every status reply taken from the input (shadow_i2c_bus.hpp checks the wire).
//
// Input: [len][mt][reply: len&15 bytes][order: 3 bytes][motor: i32]        the pure codec
//        [count][per thruster: mt-index, flags, mux, info][8 mux registers] the bus
//        then operations, [op] + its bytes, to the end (make_seeds.py writes this layout).
#include "core/thruster_config.hpp"
#include "drivers/devices/mux_tracker.hpp"
#include "drivers/devices/thruster_driver.hpp"
#include "fuzz/byte_source.hpp"
#include "fuzz/check.hpp"
#include "fuzz/shadow_i2c_bus.hpp"
#include "drivers/platform/i2c_dev.hpp"
#include "drivers/protocol/seabotix.hpp"

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <optional>
#include <vector>

using namespace caracara;
using caracara::fuzz::ByteSource;
using caracara::fuzz::ShadowI2cBus;

namespace {

uint8_t sum8(std::span<const uint8_t> b) {
    unsigned s = 0;
    for (uint8_t x : b)
        s += x;
    return static_cast<uint8_t>(s);
}

bool valid_speed(uint8_t b) { return b >= 0x19 && b <= 0xE6; }

// A SPEED byte read back as a motor value lies in range and re-encodes to the same byte
// (0x7F, the second zero, to the canonical 0x80).
void check_speed_motor(uint8_t byte, const std::optional<int32_t>& motor) {
    FUZZ_CHECK(motor.has_value() == valid_speed(byte), "SPEED %#x: value %s", byte, motor ? "given" : "missing");
    if (!motor)
        return;
    FUZZ_CHECK(*motor >= -8850 && *motor <= 8850, "SPEED %#x -> %d", byte, *motor);
    const auto back = motor_to_speed(*motor);
    FUZZ_CHECK(back && *back == (byte == 0x7F ? 0x80 : byte), "SPEED %#x -> %d -> %#x", byte, *motor, back ? *back : 0);
}

// decode_status against the IDS layout, written out here independently of the decoder.
void check_decode(Variant v, uint8_t mt, std::span<const uint8_t> r, const DecodedStatus& d) {
    const std::size_t n = v == Variant::SeaBotix ? 7 : 4;
    CodecError want = CodecError::None;
    if (r.size() != n)
        want = CodecError::BadLength;
    else if (r[0] != (mt | 1))
        want = CodecError::BadFirstByte;
    else if (sum8(r.first(n - 1)) != r[n - 1])
        want = CodecError::BadChecksum;
    FUZZ_CHECK(d.error == want, "variant %d: error %s, expected %s", static_cast<int>(v),
               std::string(codec_error_name(d.error)).c_str(), std::string(codec_error_name(want)).c_str());
    FUZZ_CHECK(d.status.variant == v, "variant not kept");
    if (!d.ok()) {
        // A refused reply yields nothing to act on.
        FUZZ_CHECK(d.status.faults.bits == 0 && !d.status.current_deciamps && !d.status.motor_stopped_by_fault(),
                   "a refused reply carries faults or a current");
        return;
    }
    const ThrusterStatus& s = d.status;
    FUZZ_CHECK((s.faults.bits & ~kFaultMask) == 0, "fault bits %#x beyond the mask", s.faults.bits);
    if (v == Variant::SeaBotix) {
        const SeaBotixStatus& x = s.seabotix;
        FUZZ_CHECK(x.status == r[1] && x.fault == r[2] && x.current == r[3] && x.speed == r[4] &&
                       x.temperature == r[5] && x.temperature_c == r[5],
                   "raw SeaBotix bytes not kept");
        FUZZ_CHECK(x.firmware_revision == r[1] >> 4 && x.brushless == ((r[1] & 2) != 0) &&
                       x.non_current_limiting == ((r[1] & 1) != 0) && x.reserved_status_bits == ((r[1] >> 2) & 3),
                   "STATUS %#x decoded wrong", r[1]);
        FUZZ_CHECK(x.faults.bits == (r[2] & 0x1F) && x.reserved_fault_bits == r[2] >> 5, "FAULT %#x decoded wrong", r[2]);
        FUZZ_CHECK(x.current_deciamps.has_value() == x.brushless && (!x.current_deciamps || *x.current_deciamps == r[3]),
                   "CURRENT given for a brushed motor or wrong");
        check_speed_motor(r[4], x.speed_motor);
        FUZZ_CHECK(s.faults == x.faults && s.current_deciamps == x.current_deciamps, "common fields differ");
        // Water detect alone keeps a SeaBotix motor running (IDS 8.4.2 remark 2).
        FUZZ_CHECK(s.motor_stopped_by_fault() == ((r[2] & 0x0F) != 0), "stop-by-fault wrong for FAULT %#x", r[2]);
        const auto again = encode_seabotix_status(mt, x.status, x.fault, x.current, x.speed, x.temperature);
        FUZZ_CHECK(std::equal(again.begin(), again.end(), r.begin()), "encode(decode(reply)) != reply");
    } else {
        const LegacyStatus& x = s.legacy;
        FUZZ_CHECK(x.status == r[1] && x.max_power == r[2], "raw legacy bytes not kept");
        FUZZ_CHECK(x.revision_code == r[1] >> 5 && x.faults.bits == (r[1] & 0x1F), "STATUS %#x decoded wrong", r[1]);
        const uint8_t code = x.revision_code;
        const LegacySoftware sw = code == 0   ? LegacySoftware::Original
                                  : code == 1 ? LegacySoftware::AveoxBrushless
                                  : code == 2 ? LegacySoftware::LegacyBrushed
                                  : code == 4 ? LegacySoftware::BrushedRev4
                                              : LegacySoftware::Unknown;
        FUZZ_CHECK(x.software == sw, "software code %u decoded wrong", code);
        const bool current = sw == LegacySoftware::AveoxBrushless;
        const bool power = sw == LegacySoftware::LegacyBrushed || sw == LegacySoftware::BrushedRev4;
        FUZZ_CHECK(x.max_power_meaning == (current ? MaxPowerMeaning::CurrentDeciAmps
                                           : power ? MaxPowerMeaning::PowerSpeed
                                                   : MaxPowerMeaning::Unknown),
                   "MAX POWER meaning wrong for code %u", code);
        FUZZ_CHECK(x.current_deciamps.has_value() == current && (!current || *x.current_deciamps == r[2]),
                   "legacy current wrong");
        if (power)
            check_speed_motor(r[2], x.power_motor);
        else
            FUZZ_CHECK(!x.power_motor, "power given for software code %u", code);
        FUZZ_CHECK(s.faults == x.faults && s.current_deciamps == x.current_deciamps, "common fields differ");
        // Every legacy fault stops the motor.
        FUZZ_CHECK(s.motor_stopped_by_fault() == ((r[1] & 0x1F) != 0), "stop-by-fault wrong for STATUS %#x", r[1]);
        const auto again = encode_legacy_status(mt, x.status, x.max_power);
        FUZZ_CHECK(std::equal(again.begin(), again.end(), r.begin()), "encode(decode(reply)) != reply");
    }
}

void pure_codec(ByteSource& in) {
    const std::size_t len = in.u8() & 0x0F;
    const uint8_t mt = in.u8();
    const auto reply = in.bytes(len);
    for (Variant v : {Variant::SeaBotix, Variant::Legacy})
        check_decode(v, mt, reply, decode_status(v, mt, reply));

    // An order as a thruster receives it: CSUM covers the address byte too (IDS 6.6.1).
    const auto order = in.bytes(3);
    const DecodedOrder o = decode_order(mt, order);
    if (order.size() != 3) {
        FUZZ_CHECK(o.error == CodecError::BadLength, "%zu-byte order not BadLength", order.size());
    } else if (static_cast<uint8_t>(mt + order[0] + order[1]) != order[2]) {
        FUZZ_CHECK(o.error == CodecError::BadChecksum, "order with a wrong CSUM accepted");
    } else {
        FUZZ_CHECK(o.error == (valid_speed(order[0]) ? CodecError::None : CodecError::BadSpeed) &&
                       o.speed == order[0] && o.info == order[1],
                   "order decoded wrong");
        if (o.error == CodecError::None && is_valid_mt(mt)) {
            const auto again = encode_order(mt, o.speed, o.info);
            FUZZ_CHECK(again && std::equal(again->begin(), again->end(), order.begin()), "encode(decode(order)) != order");
        }
    }

    // Motor value -> SPEED: refused outside -8850..8850, never clamped; within one half step.
    const int32_t value = in.i32();
    const auto speed = motor_to_speed(value);
    FUZZ_CHECK(speed.has_value() == (value >= -8850 && value <= 8850), "motor %d: speed %s", value,
               speed ? "given" : "refused");
    if (speed) {
        FUZZ_CHECK(valid_speed(*speed) && *speed != 0x7F, "motor %d -> SPEED %#x", value, *speed);
        const auto back = speed_to_motor(*speed);
        FUZZ_CHECK(back && std::abs(*back - value) <= 44, "motor %d -> %#x -> %d", value, *speed, back ? *back : 0);
        FUZZ_CHECK((*speed == 0x80) == (std::abs(value) <= 43), "motor %d: stop byte wrong", value);
        FUZZ_CHECK(value <= 0 || *speed > 0x80 || *speed == 0x80, "sign lost");
        FUZZ_CHECK(value >= 0 || *speed <= 0x80, "sign lost");
        if (is_valid_mt(mt)) {
            const auto ob = encode_order(mt, *speed, order.empty() ? kDefaultInfo : order[0]);
            FUZZ_CHECK(ob && decode_order(mt, *ob).error == CodecError::None, "encoded order does not decode");
        }
    }
}

// The status reply the target thruster gives: well formed from the input's fields, raw bytes,
// or well formed with one byte flipped (a bit error on the wire).
std::vector<uint8_t> make_reply(ByteSource& in, const ThrusterConfig& t) {
    const uint8_t mode = in.u8() % 3;
    std::vector<uint8_t> r;
    if (mode == 1) {
        const auto raw = in.bytes(status_length(t.variant));
        r.assign(raw.begin(), raw.end());
        r.resize(status_length(t.variant), 0xFF);  // an idle-high bus reads 0xFF
        return r;
    }
    if (t.variant == Variant::SeaBotix) {
        const uint8_t status = in.u8(), fault = in.u8(), current = in.u8(), speed = in.u8(), temp = in.u8();
        const auto a = encode_seabotix_status(t.mt, status, fault, current, speed, temp);
        r.assign(a.begin(), a.end());
    } else {
        const uint8_t status = in.u8(), power = in.u8();
        const auto a = encode_legacy_status(t.mt, status, power);
        r.assign(a.begin(), a.end());
    }
    if (mode == 2) {
        const uint8_t pos = in.u8(), flip = in.u8();
        r[pos % r.size()] ^= static_cast<uint8_t>(flip | 1);
    }
    return r;
}

struct StatusSnapshot {
    bool present = false;
    Variant variant = Variant::SeaBotix;
    std::array<uint8_t, 5> raw{};
    uint8_t faults = 0;
};

StatusSnapshot snapshot(const std::optional<ThrusterStatus>& s) {
    StatusSnapshot x;
    if (!s)
        return x;
    x.present = true;
    x.variant = s->variant;
    x.raw = {s->seabotix.status, s->seabotix.fault, s->seabotix.current, s->seabotix.speed, s->legacy.max_power};
    if (s->variant == Variant::Legacy)
        x.raw[0] = s->legacy.status;
    x.faults = s->faults.bits;
    return x;
}

bool same(const StatusSnapshot& a, const StatusSnapshot& b) {
    return a.present == b.present && a.variant == b.variant && a.raw == b.raw && a.faults == b.faults;
}

void bus(ByteSource& in) {
    const std::size_t count = 1 + in.u8() % 4;
    std::vector<ThrusterConfig> cfg(count);
    for (ThrusterConfig& t : cfg) {
        t.mt = static_cast<uint8_t>(0x10 + 2 * (in.u8() % 112));  // every valid MT, 0x10..0xEE
        const uint8_t flags = in.u8(), mux = in.u8();
        t.variant = flags & 1 ? Variant::Legacy : Variant::SeaBotix;
        if (flags & 2)
            t.mux = MuxRoute{static_cast<uint16_t>(kMuxAddrMin + (mux & 7)), static_cast<uint8_t>((mux >> 3) & 3)};
        t.reversed = (flags & 4) != 0;
        t.info = in.u8();
    }
    // The daemon refuses such a vehicle at start; nothing further to drive.
    if (!validate_thruster_set(cfg).empty())
        return;

    ShadowI2cBus wire(in, cfg);
    for (std::size_t i = 0; i < 8; ++i)
        wire.set_mux_control(i, in.u8());
    I2cDev dev(wire, "/dev/i2c-fuzz");
    FUZZ_CHECK(dev.open() == 0, "open failed");
    MuxTracker tracker;
    std::vector<std::unique_ptr<ThrusterDriver>> drivers;
    for (const ThrusterConfig& t : cfg)
        drivers.push_back(std::make_unique<ThrusterDriver>(dev, tracker, t));
    std::vector<uint64_t> orders(count), reads(count);

    while (!in.empty()) {
        const uint8_t op = in.u8();
        const std::size_t i = (op >> 2) % count;
        ThrusterDriver& d = *drivers[i];
        const ThrusterConfig& t = cfg[i];
        wire.target = static_cast<int>(i);
        wire.target_reached = false;
        wire.written.clear();
        const StatusSnapshot kept = snapshot(d.last_status());
        IoError e = IoError::None;
        switch (op & 3) {
        case 0: {  // an order; an i16 reaches past -8850..8850 on both sides, held to it on the wire
            const int32_t asked = in.i16();
            const int32_t value = std::clamp(asked, -8850, 8850);
            ++orders[i];
            e = d.send_order(asked);
            FUZZ_CHECK((e == IoError::None) == wire.target_reached, "order result disagrees with the wire");
            if (e == IoError::None) {
                const DecodedOrder o = decode_order(t.mt, wire.written);
                const auto want = motor_to_speed(t.reversed ? -value : value);
                FUZZ_CHECK(o.error == CodecError::None && o.speed == *want && o.info == t.info,
                           "order %d to %#x: wire speed %#x info %u", value, t.mt, o.speed, o.info);
                FUZZ_CHECK(d.last_speed() == *want, "last order not kept");
            }
            break;
        }
        case 1: {  // a status read
            wire.reply = make_reply(in, t);
            ++reads[i];
            e = d.read_status();
            if (!wire.target_reached) {
                FUZZ_CHECK(e != IoError::None && e != IoError::BadReply, "status read with no reply succeeded");
                FUZZ_CHECK(same(kept, snapshot(d.last_status())), "a failed read changed the last status");
                break;
            }
            const DecodedStatus want = decode_status(t.variant, t.mt, wire.reply);
            check_decode(t.variant, t.mt, wire.reply, want);
            if (!want.ok()) {
                FUZZ_CHECK(e == IoError::BadReply && d.last_reply_error() == want.error, "bad reply not refused");
                FUZZ_CHECK(same(kept, snapshot(d.last_status())), "a refused reply changed the last status");
            } else {
                FUZZ_CHECK(e == IoError::None && d.last_status(), "good reply not taken");
                FUZZ_CHECK(same(snapshot(want.status), snapshot(d.last_status())), "last status is not the reply");
            }
            break;
        }
        case 2:  // a mux loses its setting (brown-out): the next transfer through it NACKs
            wire.reset_mux((op >> 2) & 7);
            wire.target = -1;
            continue;
        default:  // bus recovery or a reopen: the daemon forgets every mux state
            tracker.invalidate();
            wire.target = -1;
            continue;
        }
        wire.target = -1;
        // Anything sent decides the online flag.
        FUZZ_CHECK(d.online() == (e == IoError::None), "online flag %d after %s", d.online(),
                   std::string(io_error_name(e)).c_str());
        if (e == IoError::None && t.mux) {
            const std::size_t k = t.mux->addr7 - kMuxAddrMin;
            FUZZ_CHECK(tracker.selected_channel(t.mux->addr7) == t.mux->channel &&
                           wire.mux_control(k) == (0x04 | t.mux->channel),
                       "after a good transfer the tracker and the chip disagree on mux %#x", t.mux->addr7);
            for (std::size_t m = 0; m < 8; ++m)
                if (m != k && wire.mux_present(m))
                    FUZZ_CHECK(tracker.known_disabled(static_cast<uint16_t>(kMuxAddrMin + m)) &&
                                   !(wire.mux_control(m) & 0x04),
                               "mux %#zx not disabled after thruster %zu's transfer", kMuxAddrMin + m, i);
        }
        const ThrusterCounters& c = d.counters();
        FUZZ_CHECK(c.orders_sent + c.order_failures + c.rejected_orders == orders[i], "order counters do not add up");
        FUZZ_CHECK(c.status_reads + c.status_failures == reads[i], "status counters do not add up");
        FUZZ_CHECK(c.bad_replies == c.bad_first_byte + c.bad_checksum, "bad reply counters do not add up");
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    ByteSource in(data, size);
    pure_codec(in);
    bus(in);
    return 0;
}
