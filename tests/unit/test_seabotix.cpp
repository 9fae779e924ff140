// SeaBotix codec and the thruster configuration rules. The codec vectors are worked out by hand
// from the IDS (section 8) and the Caracara packet seed; the arithmetic is next to each one.
// The driver itself runs against caracara-sim in tests/integration/test_thrusters_sim.cpp.
#include "core/thruster_config.hpp"
#include "drivers/protocol/pca9544a.hpp"
#include "drivers/protocol/seabotix.hpp"

#include "tests/catch.hpp"
#include <cerrno>
#include <cstdint>
#include <deque>
#include <limits>
#include <linux/i2c-dev.h>
#include <stdexcept>
#include <vector>

using namespace caracara;

using Bytes = std::vector<uint8_t>;

namespace {

template <std::size_t N>
Bytes bytes(const std::array<uint8_t, N>& a) {
    return Bytes(a.begin(), a.end());
}

DecodedStatus decode(Variant v, uint8_t mt, const Bytes& reply) { return decode_status(v, mt, reply); }

} // namespace

// ---------------------------------------------------------------------------------------------
// Motor value -> SPEED byte: steps = round(|v| * 102 / 8850)

TEST_CASE("motor value to SPEED byte at every boundary") {
    // 0 -> 0 steps -> the canonical zero byte 0x80
    CHECK(motor_to_speed(0) == uint8_t{0x80});
    // 8850 * 102 / 8850 = 102 -> 0x80 + 102 = 128 + 102 = 230 = 0xE6
    CHECK(motor_to_speed(8850) == uint8_t{0xE6});
    // -8850 -> 102 steps -> 0x7F - 102 = 127 - 102 = 25 = 0x19
    CHECK(motor_to_speed(-8850) == uint8_t{0x19});
    // 43 * 102 = 4386; 4386 / 8850 = 0.4956 -> 0 steps -> 0x80
    CHECK(motor_to_speed(43) == uint8_t{0x80});
    // -43: 0 steps too; the zero byte is 0x80 for either sign (not 0x7F)
    CHECK(motor_to_speed(-43) == uint8_t{0x80});
    // 44 * 102 = 4488; 4488 / 8850 = 0.5071 -> 1 step -> 0x81
    CHECK(motor_to_speed(44) == uint8_t{0x81});
    // -44 -> 1 step -> 0x7F - 1 = 0x7E
    CHECK(motor_to_speed(-44) == uint8_t{0x7E});
    // 130 * 102 = 13260; / 8850 = 1.4983 -> 1 -> 0x81
    CHECK(motor_to_speed(130) == uint8_t{0x81});
    // 131 * 102 = 13362; / 8850 = 1.5098 -> 2 -> 0x82
    CHECK(motor_to_speed(131) == uint8_t{0x82});
    // 1000 * 102 = 102000; / 8850 = 11.525 -> 12 -> 0x80 + 12 = 0x8C
    CHECK(motor_to_speed(1000) == uint8_t{0x8C});
    // -1000 -> 12 -> 0x7F - 12 = 127 - 12 = 115 = 0x73
    CHECK(motor_to_speed(-1000) == uint8_t{0x73});
    // 4425 * 102 = 451350; / 8850 = 51 exactly -> 0x80 + 51 = 179 = 0xB3
    CHECK(motor_to_speed(4425) == uint8_t{0xB3});
    // -4425 -> 51 -> 0x7F - 51 = 76 = 0x4C
    CHECK(motor_to_speed(-4425) == uint8_t{0x4C});
    // 101.5 steps lies at 101.5 * 8850 = 898275 / 102 = 8806.6:
    // 8806 * 102 = 898212 < 898275 -> 101 -> 0x80 + 101 = 0xE5
    CHECK(motor_to_speed(8806) == uint8_t{0xE5});
    // 8807 * 102 = 898314 > 898275 -> 102 -> 0xE6
    CHECK(motor_to_speed(8807) == uint8_t{0xE6});
    // -8806 -> 101 -> 0x7F - 101 = 26 = 0x1A
    CHECK(motor_to_speed(-8806) == uint8_t{0x1A});
}

TEST_CASE("out-of-range motor values are rejected, never clamped or stopped") {
    CHECK_FALSE(motor_to_speed(8851).has_value());
    CHECK_FALSE(motor_to_speed(-8851).has_value());
    CHECK_FALSE(motor_to_speed(std::numeric_limits<int32_t>::max()).has_value());
    CHECK_FALSE(motor_to_speed(std::numeric_limits<int32_t>::min()).has_value());
}

// ---------------------------------------------------------------------------------------------
// SPEED byte -> motor value: round(steps * 8850 / 102)

TEST_CASE("SPEED byte to motor value") {
    // 0x7F and 0x80 are both zero speed (IDS 8.3)
    CHECK(speed_to_motor(0x80) == 0);
    CHECK(speed_to_motor(0x7F) == 0);
    CHECK(speed_to_steps(0x80) == 0);
    CHECK(speed_to_steps(0x7F) == 0);
    // 0x81 = 1 step forward: 8850 / 102 = 86.76 -> 87
    CHECK(speed_to_steps(0x81) == 1);
    CHECK(speed_to_motor(0x81) == 87);
    // 0x7E = 1 step reverse -> -87
    CHECK(speed_to_steps(0x7E) == -1);
    CHECK(speed_to_motor(0x7E) == -87);
    // 0x82 = 2 steps: 17700 / 102 = 173.53 -> 174
    CHECK(speed_to_motor(0x82) == 174);
    // 0xB3 = 51 steps: 51 * 8850 / 102 = 4425 exactly
    CHECK(speed_to_motor(0xB3) == 4425);
    // 0xE6 = 0xE6 - 0x80 = 102 steps -> 8850; 0x19 = 0x7F - 0x19 = 102 steps reverse -> -8850
    CHECK(speed_to_steps(0xE6) == 102);
    CHECK(speed_to_motor(0xE6) == 8850);
    CHECK(speed_to_steps(0x19) == -102);
    CHECK(speed_to_motor(0x19) == -8850);
    // Outside 0x19..0xE6: invalid
    CHECK_FALSE(speed_to_motor(0x18).has_value());
    CHECK_FALSE(speed_to_motor(0xE7).has_value());
    CHECK_FALSE(speed_to_motor(0x00).has_value());
    CHECK_FALSE(speed_to_motor(0xFF).has_value());
    CHECK_FALSE(speed_to_steps(0x18).has_value());
}

TEST_CASE("SPEED mapping round-trips over the whole range") {
    // Every valid byte except the alternate zero maps back to itself.
    for (unsigned b = kSpeedMin; b <= kSpeedMax; ++b) {
        const auto v = speed_to_motor(static_cast<uint8_t>(b));
        REQUIRE(v.has_value());
        const uint8_t expect = b == 0x7F ? uint8_t{0x80} : static_cast<uint8_t>(b);
        CHECK(motor_to_speed(*v) == expect);
    }
    // Every motor value lands within half a step (8850 / 102 / 2 = 43.4) and the mapping
    // never goes backwards.
    int32_t previous = -8850;
    for (int32_t v = -8850; v <= 8850; ++v) {
        const auto s = motor_to_speed(v);
        REQUIRE(s.has_value());
        const int32_t back = *speed_to_motor(*s);
        CHECK(back - v <= 44);
        CHECK(v - back <= 44);
        CHECK(back >= previous);
        previous = back;
    }
}

// ---------------------------------------------------------------------------------------------
// Orders: [SPEED, INFO, CSUM], CSUM = (MT_write + SPEED + INFO) & 0xFF

TEST_CASE("order encoding and its checksum") {
    // MT 0x52, SPEED 0xE6, INFO 100: 0x52 + 0xE6 + 0x64 = 82 + 230 + 100 = 412 = 0x19C -> 0x9C
    CHECK(encode_order(0x52, 0xE6, 100) == OrderBytes{0xE6, 0x64, 0x9C});
    // Stop at MT 0x52: 82 + 128 + 100 = 310 = 0x136 -> 0x36
    CHECK(encode_order(0x52, 0x80) == OrderBytes{0x80, 0x64, 0x36});
    // Legacy MT 0x54, full reverse: 84 + 25 + 100 = 209 = 0xD1 (no wrap)
    CHECK(encode_order(0x54, 0x19, 100) == OrderBytes{0x19, 0x64, 0xD1});
    // Legacy stop: 84 + 128 + 100 = 312 = 0x138 -> 0x38
    CHECK(encode_order(0x54, 0x80) == OrderBytes{0x80, 0x64, 0x38});
    // INFO is not fixed: MT 0x52, SPEED 0x81, INFO 0: 82 + 129 + 0 = 211 = 0xD3
    CHECK(encode_order(0x52, 0x81, 0) == OrderBytes{0x81, 0x00, 0xD3});
    // Odd MT (a read address), reserved addresses and invalid SPEED bytes are refused.
    CHECK_FALSE(encode_order(0x53, 0x80).has_value());
    CHECK_FALSE(encode_order(0x08, 0x80).has_value());
    CHECK_FALSE(encode_order(0xF0, 0x80).has_value());
    CHECK_FALSE(encode_order(0x52, 0x18).has_value());
    CHECK_FALSE(encode_order(0x52, 0xE7).has_value());
}

TEST_CASE("order decoding as a thruster sees it") {
    // The order from above, 0x9C checksum at MT 0x52
    const Bytes good{0xE6, 0x64, 0x9C};
    auto d = decode_order(0x52, good);
    CHECK(d.error == CodecError::None);
    CHECK(d.speed == 0xE6);
    CHECK(d.info == 100);
    // The unwrapped sum's low byte plus one is wrong
    CHECK(decode_order(0x52, Bytes{0xE6, 0x64, 0x9D}).error == CodecError::BadChecksum);
    // The same bytes addressed to MT 0x54 sum to 84 + 230 + 100 = 414 = 0x19E, not 0x9C
    CHECK(decode_order(0x54, good).error == CodecError::BadChecksum);
    CHECK(decode_order(0x52, Bytes{0xE6, 0x64}).error == CodecError::BadLength);
    // SPEED 0x10 with a right checksum: 82 + 16 + 100 = 198 = 0xC6
    CHECK(decode_order(0x52, Bytes{0x10, 0x64, 0xC6}).error == CodecError::BadSpeed);
}

TEST_CASE("checksum8 is an 8-bit sum without carry") {
    CHECK(checksum8(Bytes{}) == 0);
    CHECK(checksum8(Bytes{0xFF, 0x01}) == 0x00);        // 256 -> 0
    CHECK(checksum8(Bytes{0xFF, 0xFF, 0xFF}) == 0xFD);  // 765 = 0x2FD -> 0xFD
}

// ---------------------------------------------------------------------------------------------
// Status, SeaBotix variant: [0x53, STATUS, FAULT, CURRENT, SPEED, TEMPERATURE, CSUM] at MT 0x52

TEST_CASE("SeaBotix status decodes every field") {
    // STATUS 0x03: revision 0, brushless, non current limiting; FAULT 0; CURRENT 12 = 1.2 A;
    // SPEED 0x81 (+1 step); 25 C. CSUM: 83 + 3 + 0 + 12 + 129 + 25 = 252 = 0xFC
    const auto d = decode(Variant::SeaBotix, 0x52, {0x53, 0x03, 0x00, 0x0C, 0x81, 0x19, 0xFC});
    REQUIRE(d.ok());
    const auto& s = d.status.seabotix;
    CHECK(d.status.variant == Variant::SeaBotix);
    CHECK(s.firmware_revision == 0);
    CHECK(s.brushless);
    CHECK(s.non_current_limiting);
    CHECK(s.reserved_status_bits == 0);
    CHECK_FALSE(s.faults.any());
    CHECK(s.current == 12);
    CHECK(s.current_deciamps == uint8_t{12});
    CHECK(d.status.current_deciamps == uint8_t{12});
    CHECK(s.speed == 0x81);
    CHECK(s.speed_motor == 87);
    CHECK(s.temperature_c == 25);
    CHECK_FALSE(d.status.motor_stopped_by_fault());
    // The common fields, which everything above drivers/ reads.
    CHECK(d.status.temperature_c == uint8_t{25});
    CHECK(d.status.speed_motor == 87);
    CHECK(d.status.actual_speed == 0x81);
    CHECK(d.status.firmware_revision == 0);
}

TEST_CASE("SeaBotix status with a wrapping checksum and every field at its top") {
    // STATUS 0x12: revision 1, brushless, current limited; FAULT 0x1F: all five faults;
    // CURRENT 0xFF = 25.5 A; SPEED 0xE6 (full forward); 0x6E = 110 C.
    // CSUM: 83 + 18 + 31 + 255 + 230 + 110 = 727 = 0x2D7 -> 0xD7
    const auto d = decode(Variant::SeaBotix, 0x52, {0x53, 0x12, 0x1F, 0xFF, 0xE6, 0x6E, 0xD7});
    REQUIRE(d.ok());
    const auto& s = d.status.seabotix;
    CHECK(s.firmware_revision == 1);
    CHECK(s.brushless);
    CHECK_FALSE(s.non_current_limiting);
    CHECK(s.faults.bits == 0x1F);
    for (Fault f : kAllFaults)
        CHECK(s.faults.has(f));
    CHECK(s.current_deciamps == uint8_t{255});
    CHECK(s.speed_motor == 8850);
    CHECK(s.temperature_c == 110);
    CHECK(format_faults(s.faults) == "overtemp,stall,hall,ground-fault,water-detect");
    // 0x2D7 truncated wrongly (carry kept into the low byte, 0xD9) is refused
    CHECK(decode(Variant::SeaBotix, 0x52, {0x53, 0x12, 0x1F, 0xFF, 0xE6, 0x6E, 0xD9}).error ==
          CodecError::BadChecksum);
}

TEST_CASE("SeaBotix status: each FAULT bit on its own") {
    // STATUS 0x02 (brushless), CURRENT 0, SPEED 0x80, 20 C; base sum 83 + 2 + 0 + 128 + 20 = 233
    struct Case {
        uint8_t fault;
        uint8_t csum;
        Fault expect;
        const char* name;
        bool stops;
    };
    const Case cases[] = {
        {0x01, 0xEA, Fault::Overtemp, "overtemp", true},        // 233 + 1 = 234 = 0xEA
        {0x02, 0xEB, Fault::Stall, "stall", true},              // 233 + 2 = 235 = 0xEB
        {0x04, 0xED, Fault::Hall, "hall", true},                // 233 + 4 = 237 = 0xED
        {0x08, 0xF1, Fault::GroundFault, "ground-fault", true}, // 233 + 8 = 241 = 0xF1
        {0x10, 0xF9, Fault::WaterDetect, "water-detect", false} // 233 + 16 = 249 = 0xF9; a warning
    };
    for (const Case& c : cases) {
        INFO("fault " << c.name);
        const auto d = decode(Variant::SeaBotix, 0x52, {0x53, 0x02, c.fault, 0x00, 0x80, 0x14, c.csum});
        REQUIRE(d.ok());
        CHECK(d.status.faults.bits == c.fault);
        CHECK(d.status.faults.has(c.expect));
        CHECK(fault_name(c.expect) == c.name);
        CHECK(format_faults(d.status.faults) == c.name);
        CHECK(d.status.motor_stopped_by_fault() == c.stops);
        CHECK(d.status.seabotix.speed_motor == 0);
        CHECK(d.status.seabotix.temperature_c == 20);
    }
    // FAULT bit 5 is "future growth": surfaced raw, not a fault.
    // 233 + 32 = 265 = 0x109 -> 0x09 (wraps)
    const auto d = decode(Variant::SeaBotix, 0x52, {0x53, 0x02, 0x20, 0x00, 0x80, 0x14, 0x09});
    REQUIRE(d.ok());
    CHECK_FALSE(d.status.faults.any());
    CHECK(d.status.seabotix.reserved_fault_bits == 0x01);
    CHECK(d.status.seabotix.fault == 0x20);
}

TEST_CASE("SeaBotix status: brushed motor, revision and address variants") {
    // STATUS 0x00: brushed, current limited, revision 0. CURRENT is only defined for
    // brushless software, so it is surfaced raw only.
    // CSUM: 83 + 0 + 0 + 5 + 128 + 20 = 236 = 0xEC
    auto d = decode(Variant::SeaBotix, 0x52, {0x53, 0x00, 0x00, 0x05, 0x80, 0x14, 0xEC});
    REQUIRE(d.ok());
    CHECK_FALSE(d.status.seabotix.brushless);
    CHECK(d.status.seabotix.current == 5);
    CHECK_FALSE(d.status.seabotix.current_deciamps.has_value());
    CHECK_FALSE(d.status.current_deciamps.has_value());
    // STATUS 0xFE: revision 15, reserved bits 2-3 = 3, brushless, current limited.
    // CSUM: 83 + 254 + 0 + 0 + 128 + 20 = 485 = 0x1E5 -> 0xE5
    d = decode(Variant::SeaBotix, 0x52, {0x53, 0xFE, 0x00, 0x00, 0x80, 0x14, 0xE5});
    REQUIRE(d.ok());
    CHECK(d.status.seabotix.firmware_revision == 15);
    CHECK(d.status.seabotix.reserved_status_bits == 3);
    CHECK(d.status.seabotix.brushless);
    CHECK_FALSE(d.status.seabotix.non_current_limiting);
    // A thruster at MT 0x5A answers with 0x5B. CSUM: 91 + 2 + 0 + 0 + 128 + 20 = 241 = 0xF1
    d = decode(Variant::SeaBotix, 0x5A, {0x5B, 0x02, 0x00, 0x00, 0x80, 0x14, 0xF1});
    CHECK(d.ok());
    // SPEED byte outside 0x19..0xE6 in a status (e.g. a brushed PWM value 0x05) has no motor
    // value. CSUM: 83 + 0 + 0 + 0 + 5 + 20 = 108 = 0x6C
    d = decode(Variant::SeaBotix, 0x52, {0x53, 0x00, 0x00, 0x00, 0x05, 0x14, 0x6C});
    REQUIRE(d.ok());
    CHECK(d.status.seabotix.speed == 0x05);
    CHECK_FALSE(d.status.seabotix.speed_motor.has_value());
}

TEST_CASE("SeaBotix status: bad first byte, bad checksum, bad length") {
    // First byte 0x52 (the write form) with a self-consistent checksum:
    // 82 + 3 + 0 + 12 + 129 + 25 = 251 = 0xFB
    CHECK(decode(Variant::SeaBotix, 0x52, {0x52, 0x03, 0x00, 0x0C, 0x81, 0x19, 0xFB}).error ==
          CodecError::BadFirstByte);
    // A legacy thruster's 0x55 where 0x53 is expected; 85 + 3 + 0 + 12 + 129 + 25 = 254 = 0xFE
    CHECK(decode(Variant::SeaBotix, 0x52, {0x55, 0x03, 0x00, 0x0C, 0x81, 0x19, 0xFE}).error ==
          CodecError::BadFirstByte);
    // An idle bus reads all ones
    CHECK(decode(Variant::SeaBotix, 0x52, Bytes(7, 0xFF)).error == CodecError::BadFirstByte);
    // The good reply above (sum 0xFC) with its checksum off by one
    CHECK(decode(Variant::SeaBotix, 0x52, {0x53, 0x03, 0x00, 0x0C, 0x81, 0x19, 0xFD}).error ==
          CodecError::BadChecksum);
    // One data bit flipped (CURRENT 0x0C -> 0x0D) under the original checksum
    CHECK(decode(Variant::SeaBotix, 0x52, {0x53, 0x03, 0x00, 0x0D, 0x81, 0x19, 0xFC}).error ==
          CodecError::BadChecksum);
    // Wrong lengths, including a legacy-length reply
    CHECK(decode(Variant::SeaBotix, 0x52, {0x53, 0x03, 0x00, 0x0C, 0x81, 0x19}).error == CodecError::BadLength);
    CHECK(decode(Variant::SeaBotix, 0x52, {0x53, 0x20, 0x0C, 0x7F}).error == CodecError::BadLength);
}

// ---------------------------------------------------------------------------------------------
// Status, legacy variant: [0x55, STATUS, MAX POWER, CSUM] at MT 0x54

TEST_CASE("legacy status: software revisions and the meaning of MAX POWER") {
    // Aveox brushless (bit 5 -> code 1): MAX POWER is current, 0x0C = 1.2 A.
    // CSUM: 85 + 32 + 12 = 129 = 0x81
    auto d = decode(Variant::Legacy, 0x54, {0x55, 0x20, 0x0C, 0x81});
    REQUIRE(d.ok());
    CHECK(d.status.variant == Variant::Legacy);
    CHECK(d.status.legacy.revision_code == 1);
    CHECK(d.status.legacy.software == LegacySoftware::AveoxBrushless);
    CHECK(d.status.legacy.max_power_meaning == MaxPowerMeaning::CurrentDeciAmps);
    CHECK(d.status.legacy.max_power == 0x0C);
    CHECK(d.status.legacy.current_deciamps == uint8_t{12});
    CHECK(d.status.current_deciamps == uint8_t{12});
    CHECK_FALSE(d.status.legacy.power_motor.has_value());
    CHECK_FALSE(d.status.faults.any());
    // Common fields: no temperature or SPEED in a legacy reply; MAX POWER is current here, so the
    // speed shown is the stop byte; the revision is STATUS bits 5-7.
    CHECK_FALSE(d.status.temperature_c.has_value());
    CHECK_FALSE(d.status.speed_motor.has_value());
    CHECK(d.status.actual_speed == kSpeedStop);
    CHECK(d.status.firmware_revision == 1);

    // Legacy brushed (bit 6 -> code 2): MAX POWER is the power set, in SPEED units, 0xE6 = full.
    // CSUM: 85 + 64 + 230 = 379 = 0x17B -> 0x7B (wraps)
    d = decode(Variant::Legacy, 0x54, {0x55, 0x40, 0xE6, 0x7B});
    REQUIRE(d.ok());
    CHECK(d.status.legacy.revision_code == 2);
    CHECK(d.status.legacy.software == LegacySoftware::LegacyBrushed);
    CHECK(d.status.legacy.max_power_meaning == MaxPowerMeaning::PowerSpeed);
    CHECK(d.status.legacy.power_motor == 8850);
    CHECK_FALSE(d.status.current_deciamps.has_value());
    CHECK(d.status.actual_speed == 0xE6);  // a brushed legacy's power, in SPEED units
    CHECK(d.status.firmware_revision == 2);

    // Brushed revision 4 (bit 7 -> code 4), power 0x7E = one step reverse.
    // CSUM: 85 + 128 + 126 = 339 = 0x153 -> 0x53
    d = decode(Variant::Legacy, 0x54, {0x55, 0x80, 0x7E, 0x53});
    REQUIRE(d.ok());
    CHECK(d.status.legacy.revision_code == 4);
    CHECK(d.status.legacy.software == LegacySoftware::BrushedRev4);
    CHECK(d.status.legacy.power_motor == -87);

    // Brushed with a power byte that is no SPEED value: raw only. CSUM: 85 + 64 + 5 = 154 = 0x9A
    d = decode(Variant::Legacy, 0x54, {0x55, 0x40, 0x05, 0x9A});
    REQUIRE(d.ok());
    CHECK(d.status.legacy.max_power == 5);
    CHECK_FALSE(d.status.legacy.power_motor.has_value());

    // Original software (code 0): the IDS does not say what MAX POWER is. CSUM: 85 + 0 + 16 = 101 = 0x65
    d = decode(Variant::Legacy, 0x54, {0x55, 0x00, 0x10, 0x65});
    REQUIRE(d.ok());
    CHECK(d.status.legacy.software == LegacySoftware::Original);
    CHECK(d.status.legacy.max_power_meaning == MaxPowerMeaning::Unknown);
    CHECK(d.status.legacy.max_power == 0x10);

    // Code 3 (bits 5 and 6) is not defined. CSUM: 85 + 96 + 0 = 181 = 0xB5
    d = decode(Variant::Legacy, 0x54, {0x55, 0x60, 0x00, 0xB5});
    REQUIRE(d.ok());
    CHECK(d.status.legacy.revision_code == 3);
    CHECK(d.status.legacy.software == LegacySoftware::Unknown);
    CHECK(d.status.legacy.max_power_meaning == MaxPowerMeaning::Unknown);

    CHECK(legacy_software_name(LegacySoftware::AveoxBrushless) == "aveox-brushless");
    CHECK(max_power_meaning_name(MaxPowerMeaning::PowerSpeed) == "power-speed");
}

TEST_CASE("legacy status: each STATUS fault bit on its own") {
    // STATUS 0x20 | bit, MAX POWER 0; base sum 85 + 32 + 0 = 117
    struct Case {
        uint8_t bit;
        uint8_t csum;
        Fault expect;
        bool stops;
        bool latches;
    };
    const Case cases[] = {
        {0x01, 0x76, Fault::Overtemp, true, false},     // 117 + 1 = 118 = 0x76
        {0x02, 0x77, Fault::Stall, true, false},        // 117 + 2 = 119 = 0x77
        {0x04, 0x79, Fault::Hall, true, false},         // 117 + 4 = 121 = 0x79
        {0x08, 0x7D, Fault::GroundFault, true, true},   // 117 + 8 = 125 = 0x7D
        {0x10, 0x85, Fault::WaterDetect, true, true},   // 117 + 16 = 133 = 0x85; a latched stop
    };
    for (const Case& c : cases) {
        INFO("fault " << fault_name(c.expect));
        const auto d = decode(Variant::Legacy, 0x54, {0x55, static_cast<uint8_t>(0x20 | c.bit), 0x00, c.csum});
        REQUIRE(d.ok());
        CHECK(d.status.faults.bits == c.bit);
        CHECK(d.status.faults.has(c.expect));
        CHECK(d.status.legacy.software == LegacySoftware::AveoxBrushless);  // revision bits intact
        CHECK(d.status.motor_stopped_by_fault() == c.stops);
        CHECK(fault_latches_until_power_cycle(Variant::Legacy, c.expect) == c.latches);
    }
}

TEST_CASE("legacy status: bad first byte and bad checksum") {
    // A SeaBotix reply byte 0x53 with a self-consistent checksum: 83 + 32 + 12 = 127 = 0x7F
    CHECK(decode(Variant::Legacy, 0x54, {0x53, 0x20, 0x0C, 0x7F}).error == CodecError::BadFirstByte);
    // Wrapping checksum 0x17B: the true 0x7B passes (above), 0x7C and the carry-kept 0x7D do not
    CHECK(decode(Variant::Legacy, 0x54, {0x55, 0x40, 0xE6, 0x7C}).error == CodecError::BadChecksum);
    CHECK(decode(Variant::Legacy, 0x54, {0x55, 0x40, 0xE6, 0x7D}).error == CodecError::BadChecksum);
    CHECK(decode(Variant::Legacy, 0x54, Bytes(4, 0xFF)).error == CodecError::BadFirstByte);
    CHECK(decode(Variant::Legacy, 0x54, {0x55, 0x20, 0x0C}).error == CodecError::BadLength);
}

TEST_CASE("status encoders produce what the decoder accepts") {
    // Same vectors as above, built by the simulator-side encoders.
    CHECK(bytes(encode_seabotix_status(0x52, 0x12, 0x1F, 0xFF, 0xE6, 0x6E)) ==
          Bytes{0x53, 0x12, 0x1F, 0xFF, 0xE6, 0x6E, 0xD7});
    CHECK(bytes(encode_legacy_status(0x54, 0x40, 0xE6)) == Bytes{0x55, 0x40, 0xE6, 0x7B});
}

// ---------------------------------------------------------------------------------------------
// Names and variant semantics

TEST_CASE("every variant has its row in the format table, and its status length there") {
    REQUIRE(kVariantFormats.size() == EnumNames<Variant>::table.size());
    for (const auto& [v, name] : EnumNames<Variant>::table) {
        INFO(name);
        CHECK(variant_format(v).variant == v);
    }
    CHECK(status_length(Variant::SeaBotix) == 7);  // SeaBotix IDS 8.4.2
    CHECK(status_length(Variant::Legacy) == 4);    // SeaBotix IDS 8.4.1
}

TEST_CASE("variant names and fault semantics") {
    CHECK(variant_name(Variant::SeaBotix) == "seabotix");
    CHECK(variant_name(Variant::Legacy) == "legacy");
    CHECK(parse_variant("seabotix") == Variant::SeaBotix);
    CHECK(parse_variant("legacy") == Variant::Legacy);
    CHECK_FALSE(parse_variant("SeaBotix").has_value());
    CHECK_FALSE(parse_variant("").has_value());
    CHECK(default_mt(Variant::SeaBotix) == 0x52);
    CHECK(default_mt(Variant::Legacy) == 0x54);
    CHECK(status_length(Variant::SeaBotix) == 7);
    CHECK(status_length(Variant::Legacy) == 4);
    CHECK(mt_addr7(0x52) == 0x29);
    CHECK(mt_read(0x52) == 0x53);

    // Water detect: warning on SeaBotix, latched stop on legacy.
    CHECK_FALSE(fault_stops_motor(Variant::SeaBotix, Fault::WaterDetect));
    CHECK_FALSE(fault_latches_until_power_cycle(Variant::SeaBotix, Fault::WaterDetect));
    CHECK(fault_stops_motor(Variant::Legacy, Fault::WaterDetect));
    CHECK(fault_latches_until_power_cycle(Variant::Legacy, Fault::WaterDetect));
    // Ground fault latches on both.
    CHECK(fault_latches_until_power_cycle(Variant::SeaBotix, Fault::GroundFault));
    CHECK(fault_latches_until_power_cycle(Variant::Legacy, Fault::GroundFault));
    CHECK(fault_stops_motor(Variant::SeaBotix, Fault::Overtemp));
    CHECK_FALSE(faults_stop_motor(Variant::SeaBotix, FaultSet{0x10}));
    CHECK(faults_stop_motor(Variant::SeaBotix, FaultSet{0x11}));
    CHECK(format_faults(FaultSet{}).empty());
    CHECK(format_faults(FaultSet{0x18}) == "ground-fault,water-detect");
    CHECK(codec_error_name(CodecError::BadFirstByte) == "bad-first-byte");
    CHECK(codec_error_name(CodecError::BadChecksum) == "bad-checksum");
}

// ---------------------------------------------------------------------------------------------
// Thruster configuration checks (pure). The driver's bus behaviour is tested against the real
// simulator in tests/integration/test_thrusters_sim.cpp, not against a scripted stand-in.

namespace {

ThrusterConfig seabotix_at(uint8_t mt) {
    ThrusterConfig c;
    c.mt = mt;
    c.variant = Variant::SeaBotix;
    return c;
}

ThrusterConfig behind_mux(uint8_t mt, uint16_t mux7, uint8_t channel) {
    ThrusterConfig c = seabotix_at(mt);
    c.mux = MuxRoute{mux7, channel};
    return c;
}

} // namespace

TEST_CASE("thruster configuration validation") {
    CHECK(validate_thruster_config(seabotix_at(0x52)).empty());
    CHECK_FALSE(validate_thruster_config(seabotix_at(0x53)).empty());  // odd: a read address
    CHECK_FALSE(validate_thruster_config(seabotix_at(0x08)).empty());  // addr7 0x04: reserved
    CHECK_FALSE(validate_thruster_config(seabotix_at(0xF0)).empty());  // addr7 0x78: reserved
    CHECK(validate_thruster_config(behind_mux(0x52, 0x77, 3)).empty());
    CHECK_FALSE(validate_thruster_config(behind_mux(0x52, 0x6F, 0)).empty());
    CHECK_FALSE(validate_thruster_config(behind_mux(0x52, 0x70, 4)).empty());

    const std::vector<ThrusterConfig> fine{behind_mux(0x52, 0x70, 0), behind_mux(0x52, 0x70, 1),
                                           behind_mux(0x52, 0x71, 0), seabotix_at(0x54)};
    CHECK(validate_thruster_set(fine).empty());
    const std::vector<ThrusterConfig> same_segment{behind_mux(0x52, 0x70, 0), behind_mux(0x52, 0x70, 0)};
    CHECK_FALSE(validate_thruster_set(same_segment).empty());
    const std::vector<ThrusterConfig> two_direct{seabotix_at(0x52), seabotix_at(0x52)};
    CHECK_FALSE(validate_thruster_set(two_direct).empty());
    // A trunk thruster would collide with a muxed one whenever that channel is on.
    const std::vector<ThrusterConfig> trunk_and_mux{seabotix_at(0x52), behind_mux(0x52, 0x70, 0)};
    CHECK_FALSE(validate_thruster_set(trunk_and_mux).empty());
    // MT 0xE0 is addr7 0x70, the mux itself.
    const std::vector<ThrusterConfig> on_mux_address{seabotix_at(0xE0), behind_mux(0x52, 0x70, 0)};
    CHECK_FALSE(validate_thruster_set(on_mux_address).empty());
    const std::vector<ThrusterConfig> bad_member{seabotix_at(0x52), seabotix_at(0x55)};
    CHECK(validate_thruster_set(bad_member).find("thruster 1") == 0);
}
