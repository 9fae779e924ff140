// The legacy Caracara USB packet ("Caracara USB packet format"): 13 x int32
//   [0..7]  motor0..motor7    -8850..8850
//   [8]     killState         0 = all clear, any non-zero value = kill (motors de-energized)
//   [9]     powerOffState     0 = not powered off, 1 = initiate power off (irreversible)
//   [10-12] red, green, blue  0..255 each
// Decoding validates every field; the first bad field is reported by index and name and
// the decoded packet is left empty, so a bad packet can change nothing but a kill it asks for.
#pragma once

#include "core/enum_names.hpp"
#include "core/mixing.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace caracara {

inline constexpr std::size_t kPacketWords = 13;
inline constexpr std::size_t kPacketBytes = kPacketWords * 4;

inline constexpr std::size_t kPacketKill = 8;
inline constexpr std::size_t kPacketPowerOff = 9;
inline constexpr std::size_t kPacketRed = 10;
inline constexpr std::size_t kPacketGreen = 11;
inline constexpr std::size_t kPacketBlue = 12;

// The seed's names: "motor0".."motor7", "killState", "powerOffState", "red", "green", "blue".
std::string_view packet_field_name(std::size_t index);

struct Packet {
    MotorValues motors{};
    bool kill = false;        // killState != 0
    int32_t kill_state = 0;   // the raw value, for logs
    bool power_off = false;   // powerOffState == 1
    uint8_t red = 0;
    uint8_t green = 0;
    uint8_t blue = 0;
};

enum class PacketError {
    None,
    WrongLength,        // not exactly 13 words (52 bytes)
    MotorOutOfRange,    // a motor outside -8850..8850
    BadPowerOffState,   // powerOffState other than 0 or 1 (1 is irreversible: no guessing)
    ColorOutOfRange,    // red/green/blue outside 0..255
};
template <>
struct EnumNames<PacketError> {
    static constexpr std::array<EnumName<PacketError>, 5> table{{
        {PacketError::None, "None"},
        {PacketError::WrongLength, "WrongLength"},
        {PacketError::MotorOutOfRange, "MotorOutOfRange"},
        {PacketError::BadPowerOffState, "BadPowerOffState"},
        {PacketError::ColorOutOfRange, "ColorOutOfRange"},
    }};
};
inline std::string_view error_name(PacketError v) { return name_of(v); }

struct PacketResult {
    PacketError error = PacketError::None;
    int field = -1;         // index of the offending word (-1 for WrongLength)
    Packet packet;          // default (all zero) on error
    // killState != 0 in a packet long enough to carry it, whatever else is wrong with it:
    // a kill is never lost to a bad field.
    bool kill_requested = false;
    std::string message;    // names the field index and name and the value
    bool ok() const { return error == PacketError::None; }
};

PacketResult decode_packet(std::span<const int32_t> words);
// The raw 52 bytes as a little-endian host (x86, ARM) wrote the int32 array.
PacketResult decode_packet_bytes(std::span<const uint8_t> bytes);

std::array<int32_t, kPacketWords> encode_packet(const Packet& p);

} // namespace caracara
