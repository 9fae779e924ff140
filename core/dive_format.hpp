// The dive file (docs/dive-format.md): what the recorder writes from an arming to the next
// kill or power-off, and what caracaractl plot and caracara-sim --replay read back. Pure:
// bytes in, structs out, and the reverse; the daemon's writer thread does the file I/O.
//
//   file   = header, then blocks, each appended whole (one write(2)) about once a second
//   header = "CARADIVE" u16 version u16 length <header fields> u32 crc32(fields)
//   block  = "DBLK" u32 length u32 crc32(records) <records>
//   record = u8 kind u16 length <body>; kinds: sample (every loop cycle), event, end
//
// All integers little-endian, floats IEEE-754 binary32. A reader takes every complete,
// checksummed block and names the first problem (truncated, checksum, malformed) with its
// byte offset; it never trusts a length before checking it against what is left.
#pragma once

#include "core/enum_names.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace caracara::dive {

inline constexpr std::string_view kMagic = "CARADIVE";
inline constexpr std::string_view kBlockMagic = "DBLK";
inline constexpr uint16_t kVersion = 1;
inline constexpr std::size_t kThrusters = 8;
inline constexpr std::size_t kMaxDistances = 16;       // sensors recorded per sample
inline constexpr uint32_t kMaxBlockBytes = 4u << 20;   // a block is about a second of samples
inline constexpr std::size_t kMaxText = 1024;          // reasons and client names are cut there
inline constexpr int16_t kUnknownSpeed = INT16_MIN;    // no decoded status yet

enum class RecordKind : uint8_t { Sample = 1, Event = 2, End = 3 };

// Sample flags.
enum SampleFlag : uint8_t {
    kSaturated = 1u << 0,     // the budget scaled the command
    kKillSwitch = 1u << 1,    // the kill switch read set
    kTeensyOnline = 1u << 2,
    kKillOutput = 1u << 3,    // the kill output asserted
    // bits 4-5: the bus state (0 ok, 1 recovering, 2 lost)
};
inline constexpr unsigned kBusStateShift = 4;

// Per-thruster flags.
enum ThrusterFlag : uint8_t {
    kOnline = 1u << 0,        // its last transaction succeeded
    kStatusKnown = 1u << 1,   // speed, temperature and faults come from a decoded reply
    kCurrentKnown = 1u << 2,  // the reply carries a motor current
};

struct Header {
    uint64_t start_unix_ms = 0;   // wall clock at the dive's start (for names and listings)
    uint64_t start_mono_ns = 0;   // CLOCK_MONOTONIC at the start (to match the journal)
    uint32_t loop_rate_hz = 0;
    std::string profile;          // the thrust profile at the start
    std::string reason;           // what started it: "clear-kill", "start"
};

struct ThrusterSample {
    int16_t speed = kUnknownSpeed;  // the reported SPEED as a motor value
    uint8_t current_da = 0;         // 0.1 A
    uint8_t temperature_c = 0;
    uint8_t faults = 0;             // the FAULT bits (kFaultMask)
    uint8_t flags = 0;              // ThrusterFlag
    uint32_t nacks = 0;             // since the daemon started (counters only grow)
    uint32_t bad_replies = 0;
    uint32_t errors = 0;            // failed transactions of any kind
    bool operator==(const ThrusterSample&) const = default;
};

struct Sample {
    uint32_t t_100us = 0;           // since the dive's start, 0.1 ms
    std::array<int16_t, kThrusters> requested{};
    std::array<int16_t, kThrusters> applied{};
    int16_t budget_limit = 0;
    uint8_t flags = 0;              // SampleFlag and the bus state
    std::array<ThrusterSample, kThrusters> thrusters{};
    std::array<float, 3> orientation{};  // yaw, pitch, roll (radians, as the Teensy reports)
    std::vector<uint16_t> distances;     // mm
    uint32_t bus_errors = 0;
    uint32_t bus_recoveries = 0;
    unsigned bus_state() const { return (flags >> kBusStateShift) & 3u; }
    bool operator==(const Sample&) const = default;
};

enum class EventKind : uint8_t {
    State = 1,        // state (SafetyState), kill_source, text = reason, client
    Fault = 2,        // thruster, value = the new fault bits
    BusLost = 3,      // text = reason
    BusRestored = 4,  // value = SCL pulses, number = milliseconds
    Profile = 5,      // text = name, number = factor
    Failsafe = 6,     // text = "<condition> <action>", thruster, value = kFailsafe* bits
    MotorTest = 7,    // thruster, value = kOn (started or changed; else stopped), number = its value, client
    Detection = 8,    // a direction detection run: value = kOn (started; else ended), number = thrusters judged, client
    DetectionPulse = 9,   // thruster, value = kOn (pulse ordered; else ordered zero), number = the pulse's value
    DetectionResult = 10, // thruster, value = the verdict (DirectionVerdict), number = margin,
                          // text = "yaw=... pitch=... roll=... along=..." (rad)
};
// A motor test's, detection's or pulse's value bit.
inline constexpr uint32_t kOn = 1u << 0;
inline constexpr uint32_t kMaxVerdict = 2; // DirectionVerdict::Inconclusive
// A failsafe event's value bits.
inline constexpr uint32_t kFailsafeRaised = 1u << 0;  // raised (else cleared)
inline constexpr uint32_t kFailsafeVehicle = 1u << 1; // the vehicle's own, not `thruster`'s
} // namespace caracara::dive
namespace caracara {
template <>
struct EnumNames<dive::EventKind> {
    static constexpr std::array<EnumName<dive::EventKind>, 10> table{{
        {dive::EventKind::State, "state"},
        {dive::EventKind::Fault, "fault"},
        {dive::EventKind::BusLost, "bus-lost"},
        {dive::EventKind::BusRestored, "bus-restored"},
        {dive::EventKind::Profile, "profile"},
        {dive::EventKind::Failsafe, "failsafe"},
        {dive::EventKind::MotorTest, "motor-test"},
        {dive::EventKind::Detection, "detection"},
        {dive::EventKind::DetectionPulse, "detection-pulse"},
        {dive::EventKind::DetectionResult, "detection-result"},
    }};
};
} // namespace caracara
namespace caracara::dive {
inline std::string_view event_kind_name(EventKind v) { return name_of(v); }

struct Event {
    uint32_t t_100us = 0;
    EventKind kind = EventKind::State;
    uint8_t state = 0;        // SafetyState as its enum value
    uint8_t kill_source = 0;  // KillSource as its enum value
    uint8_t thruster = 0;
    uint32_t value = 0;
    float number = 0;
    std::string text;
    std::string client;
    bool operator==(const Event&) const = default;
};

// What closed the dive: the state it ended in (a kill, a power-off) or the daemon stopping.
struct End {
    uint32_t t_100us = 0;
    std::string reason;
    bool operator==(const End&) const = default;
};

// --- writing ----------------------------------------------------------------------------------

std::vector<uint8_t> encode_header(const Header& h);
// Records go into `records`; seal_block() makes one block of them for the file.
void encode_sample(std::vector<uint8_t>& records, const Sample& s);
void encode_event(std::vector<uint8_t>& records, const Event& e);
void encode_end(std::vector<uint8_t>& records, const End& e);
std::vector<uint8_t> seal_block(std::span<const uint8_t> records);

// --- reading ----------------------------------------------------------------------------------

enum class ReadError : uint8_t {
    None,
    NotADive,      // no "CARADIVE" at the start
    Version,       // a version this reader does not know
    Truncated,     // the file ends inside the header or a block
    Checksum,      // a header or block whose CRC-32 does not match
    Malformed,     // a block or record whose lengths or values make no sense
};
} // namespace caracara::dive
namespace caracara {
template <>
struct EnumNames<dive::ReadError> {
    static constexpr std::array<EnumName<dive::ReadError>, 6> table{{
        {dive::ReadError::None, "ok"},
        {dive::ReadError::NotADive, "not-a-dive"},
        {dive::ReadError::Version, "version"},
        {dive::ReadError::Truncated, "truncated"},
        {dive::ReadError::Checksum, "checksum"},
        {dive::ReadError::Malformed, "malformed"},
    }};
};
} // namespace caracara
namespace caracara::dive {
inline std::string_view read_error_name(ReadError v) { return name_of(v); }

struct Dive {
    Header header;
    std::vector<Sample> samples;
    std::vector<Event> events;
    bool ended = false;       // an end record was read: the dive was closed
    End end;
    ReadError error = ReadError::None;
    std::size_t error_offset = 0;  // byte offset of the first problem
    std::string message;           // "truncated at byte 1234: block of 5000 bytes, 200 left"
    bool ok() const { return error == ReadError::None; }
};

// Decodes a whole file. On an error the result keeps everything read before it.
Dive decode(std::span<const uint8_t> bytes);

} // namespace caracara::dive
