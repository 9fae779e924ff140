// SeaBotix thruster controller codec (IDS "LBV Motherboard / Thruster Motor Controller",
// 19 Mar 2009; section 8 takes precedence). Pure functions, no system calls, no heap, so the
// daemon, the simulator and the unit tests share one definition of the wire format.
//
// Wire format (the "MT" byte is the 8-bit I2C address byte, addr7 << 1 | R/W):
//   order  (write to addr7): [SPEED, INFO, CSUM]        CSUM = MT_write + SPEED + INFO (mod 256)
//   status (plain read):     SeaBotix [MT_read, STATUS, FAULT, CURRENT, SPEED, TEMPERATURE, CSUM]
//                            legacy   [MT_read, STATUS, MAX POWER, CSUM]
//                            CSUM = sum of the bytes before it (mod 256)
// The IDS's 8.4.2 says the SeaBotix reply answers "read command 57h"; its own 6.4.2 and the
// reply's MT=53h say 52h/53h, which is what this codec uses (the address is configurable anyway).
#pragma once

#include "core/enum_names.hpp"
#include "core/motor.hpp"
#include "core/thruster_config.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace caracara {


// The controller variants, one row each: the length of a status reply. This table and the codec
// below (decode_status, which says what each reply carries) are the one place the variants are
// told apart; code above drivers/ reads the common fields of ThrusterStatus (temperature_c,
// speed_motor, actual_speed, firmware_revision) and never tests the variant (tests/layers.py checks).
struct VariantFormat {
    Variant variant;
    std::size_t status_length;  // bytes, first byte and checksum included
};
inline constexpr std::array<VariantFormat, 2> kVariantFormats{{
    {Variant::SeaBotix, 7},  // [MT_read, STATUS, FAULT, CURRENT, SPEED, TEMPERATURE, CSUM] (IDS 8.4.2)
    {Variant::Legacy, 4},    // [MT_read, STATUS, MAX POWER, CSUM] (IDS 8.4.1)
}};
constexpr const VariantFormat& variant_format(Variant v) {
    for (const VariantFormat& f : kVariantFormats)
        if (f.variant == v)
            return f;
    return kVariantFormats[0];
}
constexpr std::size_t status_length(Variant v) { return variant_format(v).status_length; }
inline constexpr std::size_t kMaxStatusLength = 7;
static_assert(kVariantFormats[0].status_length <= kMaxStatusLength && kVariantFormats[1].status_length <= kMaxStatusLength);
inline constexpr std::size_t kOrderLength = 3;  // bytes after the address byte


// Motor values (Caracara packet seed) and SPEED bytes (IDS 8.3).
inline constexpr int32_t kSpeedSteps = 102;  // discrete speeds each way (IDS 6.2)
inline constexpr uint8_t kSpeedStop = 0x80;  // the zero byte this codec sends
inline constexpr uint8_t kSpeedStopAlt = 0x7F; // also zero per the IDS; accepted, never sent
inline constexpr uint8_t kSpeedMin = 0x19;   // full reverse
inline constexpr uint8_t kSpeedMax = 0xE6;   // full forward

// Motor value -8850..+8850 -> SPEED byte. steps = round(|v| * 102 / 8850), half away from
// zero; v > 0 -> 0x80 + steps, v < 0 -> 0x7F - steps. Every value that rounds to zero steps
// (|v| <= 43, either sign) gives 0x80, so "stopped" is one byte on the wire and in the logs.
// Out of range -> nullopt: never clamped, never turned into a stop.
std::optional<uint8_t> motor_to_speed(int32_t value);
// SPEED byte -> signed steps -102..+102 (0x7F and 0x80 -> 0); nullopt outside 0x19..0xE6.
std::optional<int32_t> speed_to_steps(uint8_t speed);
// SPEED byte -> motor value, round(steps * 8850 / 102) with the sign of the steps;
// nullopt outside 0x19..0xE6. motor_to_speed(speed_to_motor(b)) == b for every valid b
// except 0x7F (which maps back to the canonical 0x80).
std::optional<int32_t> speed_to_motor(uint8_t speed);

// 8-bit unsigned sum without carry (IDS "CSUM").
uint8_t checksum8(std::span<const uint8_t> bytes);

// Encoding/decoding failures, named for counters and logs.
enum class CodecError : uint8_t {
    None = 0,
    BadLength,     // wrong number of bytes for the message
    BadFirstByte,  // status reply's first byte is not MT_read of the addressed thruster
    BadChecksum,   // CSUM does not match
    BadSpeed,      // SPEED byte outside 0x19..0xE6
    BadAddress,    // MT is odd or a reserved I2C address
};
template <>
struct EnumNames<CodecError> {
    static constexpr std::array<EnumName<CodecError>, 6> table{{
        {CodecError::None, "none"},
        {CodecError::BadLength, "bad-length"},
        {CodecError::BadFirstByte, "bad-first-byte"},
        {CodecError::BadChecksum, "bad-checksum"},
        {CodecError::BadSpeed, "bad-speed"},
        {CodecError::BadAddress, "bad-address"},
    }};
};
inline std::string_view codec_error_name(CodecError v) { return name_of(v); }

using OrderBytes = std::array<uint8_t, kOrderLength>;

// The bytes written after the address byte: [SPEED, INFO, CSUM], CSUM = MT + SPEED + INFO.
// nullopt when `mt_write` is not a valid MT or `speed` is outside 0x19..0xE6.
std::optional<OrderBytes> encode_order(uint8_t mt_write, uint8_t speed, uint8_t info = kDefaultInfo);

// Order as a thruster receives it (the simulator's side). A thruster discards an order whose
// checksum is wrong (IDS 6.6.1); BadSpeed is reported separately so the caller decides.
struct DecodedOrder {
    CodecError error = CodecError::None;
    uint8_t speed = kSpeedStop;
    uint8_t info = kDefaultInfo;
};
DecodedOrder decode_order(uint8_t mt_write, std::span<const uint8_t> bytes);

// Fault conditions. The bit positions are those of the SeaBotix FAULT byte, which are also
// the positions of the legacy STATUS bits 0-4, so one mask serves both variants.
enum class Fault : uint8_t {
    Overtemp = 0,
    Stall = 1,
    Hall = 2,
    GroundFault = 3,
    WaterDetect = 4,
};
inline constexpr std::array<Fault, 5> kAllFaults{Fault::Overtemp, Fault::Stall, Fault::Hall,
                                                 Fault::GroundFault, Fault::WaterDetect};
inline constexpr uint8_t kFaultMask = 0x1F;

// "overtemp", "stall", "hall", "ground-fault", "water-detect"
template <>
struct EnumNames<Fault> {
    static constexpr std::array<EnumName<Fault>, 5> table{{
        {Fault::Overtemp, "overtemp"},
        {Fault::Stall, "stall"},
        {Fault::Hall, "hall"},
        {Fault::GroundFault, "ground-fault"},
        {Fault::WaterDetect, "water-detect"},
    }};
};
inline std::string_view fault_name(Fault f) { return name_of(f); }

struct FaultSet {
    uint8_t bits = 0;  // only kFaultMask bits are ever set
    constexpr bool has(Fault f) const { return (bits >> static_cast<unsigned>(f)) & 0x01; }
    constexpr bool any() const { return bits != 0; }
    constexpr bool operator==(const FaultSet&) const = default;
};
constexpr FaultSet fault_set_from_bits(uint8_t bits) { return FaultSet{static_cast<uint8_t>(bits & kFaultMask)}; }
// Comma-separated names in bit order, "" when none ("overtemp,water-detect").
std::string format_faults(FaultSet faults);

// Variant semantics from the IDS remarks (8.4.1 / 8.4.2), surfaced as the firmware has them:
// - Water detect: SeaBotix keeps driving (an early warning, clears when the resistance
//   recovers); legacy stops the motor and latches until power is cycled.
// - Ground fault: both stop and latch until power is cycled.
// - Overtemp (clears at 100 C), stall, hall: both stop; the IDS names no power-cycle latch.
bool fault_stops_motor(Variant v, Fault f);
bool fault_latches_until_power_cycle(Variant v, Fault f);
bool faults_stop_motor(Variant v, FaultSet faults);

// Legacy STATUS bits 5-7: the software revision code (IDS 8.4.1).
enum class LegacySoftware : uint8_t {
    Original,        // code 0: original software, all bits zero
    AveoxBrushless,  // code 1 (bit 5): brushless DC, first revision (Aveox)
    LegacyBrushed,   // code 2 (bit 6): brushed DC, first revision (SeaBotix legacy)
    BrushedRev4,     // code 4 (bit 7): brushed DC, revision 4
    Unknown,         // codes 3, 5, 6, 7: not defined by the IDS
};
template <>
struct EnumNames<LegacySoftware> {
    static constexpr std::array<EnumName<LegacySoftware>, 5> table{{
        {LegacySoftware::Original, "original"},
        {LegacySoftware::AveoxBrushless, "aveox-brushless"},
        {LegacySoftware::LegacyBrushed, "legacy-brushed"},
        {LegacySoftware::BrushedRev4, "brushed-rev4"},
        {LegacySoftware::Unknown, "unknown"},
    }};
};
inline std::string_view legacy_software_name(LegacySoftware v) { return name_of(v); }

// What the legacy MAX POWER byte means depends on the software (IDS 8.4.1).
enum class MaxPowerMeaning : uint8_t {
    CurrentDeciAmps,  // brushless software: motor current in 0.1 A
    PowerSpeed,       // brushed software: power set into the motor, in SPEED byte units
    Unknown,          // original or undefined software: the IDS does not say
};
template <>
struct EnumNames<MaxPowerMeaning> {
    static constexpr std::array<EnumName<MaxPowerMeaning>, 3> table{{
        {MaxPowerMeaning::CurrentDeciAmps, "current"},
        {MaxPowerMeaning::PowerSpeed, "power-speed"},
        {MaxPowerMeaning::Unknown, "unknown"},
    }};
};
inline std::string_view max_power_meaning_name(MaxPowerMeaning v) { return name_of(v); }

struct SeaBotixStatus {
    // Raw bytes as received.
    uint8_t status = 0;
    uint8_t fault = 0;
    uint8_t current = 0;
    uint8_t speed = 0;
    uint8_t temperature = 0;
    // STATUS decoded.
    uint8_t firmware_revision = 0;      // bits 4-7
    bool brushless = false;             // bit 1: 1 brushless, 0 brushed
    bool non_current_limiting = false;  // bit 0: 1 non current limiting, 0 current limited
    uint8_t reserved_status_bits = 0;   // bits 2-3 ("future growth") as 0..3
    // FAULT decoded; bits 5-7 are "future growth" and kept in reserved_fault_bits.
    FaultSet faults;
    uint8_t reserved_fault_bits = 0;
    // CURRENT in 0.1 A; the IDS defines it for brushless software only, so this is nullopt
    // when STATUS says brushed (the raw byte stays in `current`).
    std::optional<uint8_t> current_deciamps;
    // SPEED as a motor value; nullopt when the byte is outside 0x19..0xE6. For brushed motors
    // the IDS says the byte is the PWM value, so this is a reading of it in SPEED units.
    std::optional<int32_t> speed_motor;
    // TEMPERATURE in deg C (motor; controller for brushed motors).
    uint8_t temperature_c = 0;
};

struct LegacyStatus {
    // Raw bytes as received.
    uint8_t status = 0;
    uint8_t max_power = 0;
    // STATUS decoded.
    uint8_t revision_code = 0;  // bits 5-7 as 0..7
    LegacySoftware software = LegacySoftware::Original;
    FaultSet faults;            // bits 0-3 and bit 4 (water detect)
    // MAX POWER interpreted; the raw byte stays in max_power.
    MaxPowerMeaning max_power_meaning = MaxPowerMeaning::Unknown;
    std::optional<uint8_t> current_deciamps;  // when meaning == CurrentDeciAmps
    std::optional<int32_t> power_motor;       // when meaning == PowerSpeed and the byte is a valid SPEED
};

// A decoded status reply of either variant; only the member of `variant` is meaningful. The
// fields before it are common: what the daemon, the dive files and D-Bus read.
struct ThrusterStatus {
    Variant variant = Variant::SeaBotix;
    FaultSet faults;                          // common to both variants
    std::optional<uint8_t> current_deciamps;  // when the reply carries a motor current
    std::optional<uint8_t> temperature_c;     // when the reply carries a temperature
    std::optional<int32_t> speed_motor;       // the SPEED read back as a motor value, when carried and valid
    uint8_t actual_speed = kSpeedStop;        // SPEED byte, or a brushed legacy's power in SPEED units; else stop
    uint8_t firmware_revision = 0;            // the STATUS byte's revision field
    SeaBotixStatus seabotix;
    LegacyStatus legacy;

    bool motor_stopped_by_fault() const { return faults_stop_motor(variant, faults); }
};

struct DecodedStatus {
    CodecError error = CodecError::None;
    ThrusterStatus status;
    bool ok() const { return error == CodecError::None; }
};

// Decodes a status reply read from the thruster at `mt_write`. Checks, in order: length
// (status_length(v)), first byte == MT_read, checksum. A failed reply must be discarded.
DecodedStatus decode_status(Variant v, uint8_t mt_write, std::span<const uint8_t> reply);

// Status replies as a thruster sends them (the simulator's side); CSUM is computed.
std::array<uint8_t, 7> encode_seabotix_status(uint8_t mt_write, uint8_t status, uint8_t fault,
                                              uint8_t current, uint8_t speed, uint8_t temperature);
std::array<uint8_t, 4> encode_legacy_status(uint8_t mt_write, uint8_t status, uint8_t max_power);

} // namespace caracara
