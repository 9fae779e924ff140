// What a bus scan (docs/commissioning.md, "Bus scan") found, judged against the configuration:
// which addresses it probes where, and for each configured thruster whether it answered where
// the configuration puts it (ok), nowhere (missing), elsewhere (moved) or as the other
// controller variant (wrong variant); whatever answered and is no configured thruster is
// unexpected. Pure: daemon/commissioning/bus_scan probes, this judges.
#pragma once

#include "core/enum_names.hpp"
#include "core/thruster_config.hpp"

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace caracara {

enum class ScanVerdict : uint8_t { Ok, Missing, Moved, WrongVariant };
template <>
struct EnumNames<ScanVerdict> {
    static constexpr std::array<EnumName<ScanVerdict>, 4> table{{
        {ScanVerdict::Ok, "ok"},
        {ScanVerdict::Missing, "missing"},
        {ScanVerdict::Moved, "moved"},
        {ScanVerdict::WrongVariant, "wrong-variant"},
    }};
};
inline std::string_view scan_verdict_name(ScanVerdict v) { return name_of(v); }

// Where a device sits: on the trunk (no mux channel enabled) or behind one mux channel.
using ScanSegment = std::optional<MuxRoute>;
bool same_segment(const ScanSegment& a, const ScanSegment& b);
// "trunk", "mux 0x70 channel 2"
std::string segment_text(const ScanSegment& s);

// One device that answered a probe.
struct ScanDevice {
    ScanSegment segment;
    uint8_t mt = 0;                 // the 8-bit write address byte it answered at
    std::optional<Variant> variant; // nullopt: it answered, but not with a thruster's status reply
    uint8_t revision = 0;           // the STATUS byte's software revision (SeaBotix bits 4-7, legacy 5-7)
    int32_t thruster = -1;          // the configured thruster it was taken for, or -1: unexpected
};

struct ThrusterScan {
    ScanVerdict verdict = ScanVerdict::Missing;
    int32_t device = -1; // index into BusScanReport::devices, or -1
    std::string advice;  // what to do; "" when ok
};

struct BusScanReport {
    std::vector<ScanDevice> devices;
    std::vector<ThrusterScan> thrusters;
    // Every thruster ok and nothing unexpected: the bus is what the configuration says.
    bool matches() const;
};

// The addresses probed on each segment: the two the SeaBotix IDS names (6.4.2: 0x52 SeaBotix,
// 0x54 Aveox/legacy) and every address the configuration gives a thruster, ascending.
std::vector<uint8_t> scan_addresses(std::span<const ThrusterConfig> thrusters);
// The segments probed: the trunk, then the four channels of each mux the configuration names.
std::vector<ScanSegment> scan_segments(std::span<const ThrusterConfig> thrusters);

// Adds a device that answered, unless it is one that answered on the trunk: with a channel
// enabled the trunk is on the bus too, so a trunk device answers on every channel. The trunk is
// probed first. False when it was left out.
bool add_scan_device(BusScanReport& report, const ScanDevice& device);

// Fills report.thrusters (one per configured thruster) and each device's `thruster`: a device
// at a thruster's segment and address is that thruster (ok, or wrong variant); a thruster not
// found there is taken to be an unclaimed device at its address on another segment (moved), or
// else the one unclaimed device at another address on its own segment (moved); else missing.
void judge_bus_scan(std::span<const ThrusterConfig> thrusters, BusScanReport& report);

} // namespace caracara
