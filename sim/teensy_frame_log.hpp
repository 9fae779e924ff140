// What the simulated Teensy (sim/teensy_model) saw, for inspection and tests: its last frames
// (a bounded log, oldest first) and counts per command and per outcome.
#pragma once

#include "sim/teensy_frame_record.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <vector>

namespace caracara::sim {

class TeensyFrameLog final {
public:
    explicit TeensyFrameLog(std::size_t capacity) : capacity_(capacity) {}
    void received(uint8_t command) { ++received_[command]; }
    void executed(uint8_t command) { ++executed_[command]; }
    // Numbers the frame (seq), counts its outcome and drops the oldest past the capacity.
    void add(TeensyFrameRecord r);

    std::vector<TeensyFrameRecord> records() const { return {log_.begin(), log_.end()}; } // oldest first
    uint64_t total() const { return next_seq_; }
    // Frames whose command byte was seen / that were executed (Ok or GarbageAck).
    uint64_t commands_received(uint8_t command) const { return received_[command]; }
    uint64_t commands_executed(uint8_t command) const { return executed_[command]; }
    uint64_t outcome_count(TeensyFrameOutcome o) const { return outcomes_[static_cast<std::size_t>(o)]; }

private:
    std::size_t capacity_;
    std::deque<TeensyFrameRecord> log_;
    uint64_t next_seq_ = 0;
    std::array<uint64_t, 256> received_{};
    std::array<uint64_t, 256> executed_{};
    std::array<uint64_t, 7> outcomes_{};
};

} // namespace caracara::sim
