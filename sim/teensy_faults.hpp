// The faults injected into the simulated Teensy (sim/teensy_model: what each one models is told
// there): for each frame of a known command, decided when its command byte arrives, the first
// matching rule wins: no answer, garbage ack, busy (N frames, then with a probability from a
// seeded RNG).
#pragma once

#include <cstdint>

namespace caracara::sim {

enum class TeensyFramePlan : uint8_t { Normal, Busy, Garbage, NoAnswer };

class TeensyFaults final {
public:
    void inject_busy(unsigned frames) { busy_frames_ = frames; }
    // false (and nothing changes) unless 0 <= probability <= 1.
    bool set_random_busy(double probability, uint64_t seed);
    void inject_garbage_ack(unsigned frames) { garbage_frames_ = frames; }
    void inject_no_answer(unsigned frames) { no_answer_frames_ = frames; }
    void clear();
    unsigned pending_busy() const { return busy_frames_; }
    unsigned pending_garbage_ack() const { return garbage_frames_; }
    unsigned pending_no_answer() const { return no_answer_frames_; }
    double random_busy_probability() const { return busy_probability_; }

    // The next frame's plan (counts one frame off the rule that matched).
    TeensyFramePlan next();

private:
    bool next_random_busy();

    unsigned busy_frames_ = 0;
    unsigned garbage_frames_ = 0;
    unsigned no_answer_frames_ = 0;
    double busy_probability_ = 0.0;
    uint64_t rng_state_ = 0;
};

} // namespace caracara::sim
