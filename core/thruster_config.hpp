// A thruster as the configuration describes it: which controller variant, at which address,
// behind which PCA9544A channel, mounted which way; and the rules a set of them must follow.
// One definition for the configuration checker, the drivers and the simulator.
#pragma once

#include "core/enum_names.hpp"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace caracara {

// Which controller firmware answers: they share the order format but not the status reply.
enum class Variant : uint8_t {
    SeaBotix,  // SeaBotix controller, default MT 0x52/0x53, 7-byte status
    Legacy,    // Aveox / legacy SeaBotix controller, default MT 0x54/0x55, 4-byte status
};

template <>
struct EnumNames<Variant> {
    static constexpr std::array<EnumName<Variant>, 2> table{{
        {Variant::SeaBotix, "seabotix"},
        {Variant::Legacy, "legacy"},
    }};
};
inline std::string_view variant_name(Variant v) { return name_of(v); }
inline std::optional<Variant> parse_variant(std::string_view s) { return parse_name<Variant>(s); }

// Default 8-bit write address byte (MT) from IDS 6.4.2.
constexpr uint8_t default_mt(Variant v) { return v == Variant::SeaBotix ? 0x52 : 0x54; }
// MT helpers. A valid MT is even (it is the write form) and its 7-bit address is outside the
// I2C reserved ranges (0x00-0x07, 0x78-0x7F), i.e. MT 0x10..0xEE.
constexpr uint16_t mt_addr7(uint8_t mt_write) { return static_cast<uint16_t>(mt_write >> 1); }
constexpr uint8_t mt_read(uint8_t mt_write) { return static_cast<uint8_t>(mt_write | 0x01); }
constexpr bool is_valid_mt(uint8_t mt) { return (mt & 0x01) == 0 && mt >= 0x10 && mt <= 0xEE; }

inline constexpr uint8_t kDefaultInfo = 100; // SeaBotix IDS 8.3: INFO "Currently set to 100"

// PCA9544A: 4-channel I2C multiplexer, 7-bit address 1110 A2 A1 A0 (0x70..0x77). Its
// control register is written with a single byte: bit 2 enables, bits 1-0 pick the channel;
// 0x00 disconnects every channel.
inline constexpr uint16_t kMuxAddrMin = 0x70;
inline constexpr uint16_t kMuxAddrMax = 0x77;
inline constexpr uint16_t kDefaultMuxAddr7 = 0x70;
inline constexpr uint8_t kMuxChannels = 4;
constexpr bool is_valid_mux_addr7(uint16_t addr7) { return addr7 >= kMuxAddrMin && addr7 <= kMuxAddrMax; }

struct MuxRoute {
    uint16_t addr7 = kDefaultMuxAddr7;  // PCA9544A 7-bit address
    uint8_t channel = 0;                // 0..3
};

struct ThrusterConfig {
    uint8_t mt = default_mt(Variant::SeaBotix);  // 8-bit write address byte (even); addr7 = mt >> 1
    Variant variant = Variant::SeaBotix;
    uint8_t info = kDefaultInfo;
    std::optional<MuxRoute> mux;                 // when the thruster sits behind a PCA9544A
    bool reversed = false;                       // negate motor values (mounting direction)
};

// A set-level conflict between two thrusters (the one rule set for the drivers and the
// configuration checker, which words them with keys and lines).
struct ThrusterConflict {
    enum class Kind {
        MuxAddress,    // `thruster`'s address is the address of the mux `other` sits behind
        SharedAddress, // `thruster` and `other` (other < thruster) answer at one address on one segment
    } kind;
    std::size_t thruster;
    std::size_t other;
};
// Every conflict in `set`, skipping the thrusters marked invalid in `valid` (empty: all valid).
std::vector<ThrusterConflict> thruster_conflicts(std::span<const ThrusterConfig> set, std::span<const bool> valid = {});

// "" when valid, else a message naming the bad field.
std::string validate_thruster_config(const ThrusterConfig& cfg);
// Whole-bus checks on top of validate_thruster_config: no two thrusters reachable at the same
// (mux, channel, address); a thruster on the trunk (no mux) shares its address with no other
// thruster, because an enabled mux channel joins its segment to the trunk; no thruster uses
// the address of a mux on the bus.
std::string validate_thruster_set(std::span<const ThrusterConfig> set);

} // namespace caracara
