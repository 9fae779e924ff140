// One SPI frame as the simulated Teensy (sim/teensy_model) saw it, for its frame log: what came
// in, what went out, and what became of it.
#pragma once

#include "core/enum_names.hpp"

#include <cstdint>
#include <string_view>
#include <vector>

namespace caracara::sim {

enum class TeensyFrameOutcome : uint8_t {
    Ok,         // executed, ack = command
    Busy,       // ack 0xFF, not executed
    GarbageAck, // executed, ack corrupted
    NoAnswer,   // all zeros, not executed
    Invalid,    // bad argument, ack 0x00, not executed
    Unknown,    // unknown command id, zeros until chip select release
    Incomplete, // chip select released before the ack slot, not executed
};

struct TeensyFrameRecord {
    uint64_t seq = 0; // running number over the model's lifetime, for incremental readers
    uint64_t start_ns = 0;
    uint64_t end_ns = 0;
    uint8_t command = 0;
    std::string_view name;
    TeensyFrameOutcome outcome = TeensyFrameOutcome::Ok;
    std::vector<uint8_t> mosi;
    std::vector<uint8_t> miso;
};

} // namespace caracara::sim
namespace caracara {
template <>
struct EnumNames<sim::TeensyFrameOutcome> {
    static constexpr std::array<EnumName<sim::TeensyFrameOutcome>, 7> table{{
        {sim::TeensyFrameOutcome::Ok, "ok"},
        {sim::TeensyFrameOutcome::Busy, "busy"},
        {sim::TeensyFrameOutcome::GarbageAck, "garbage-ack"},
        {sim::TeensyFrameOutcome::NoAnswer, "no-answer"},
        {sim::TeensyFrameOutcome::Invalid, "invalid"},
        {sim::TeensyFrameOutcome::Unknown, "unknown"},
        {sim::TeensyFrameOutcome::Incomplete, "incomplete"},
    }};
};
} // namespace caracara
