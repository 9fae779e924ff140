#include "sim/teensy_faults.hpp"

namespace caracara::sim {

TeensyFramePlan TeensyFaults::next() {
    if (no_answer_frames_ > 0) {
        --no_answer_frames_;
        return TeensyFramePlan::NoAnswer;
    }
    if (garbage_frames_ > 0) {
        --garbage_frames_;
        return TeensyFramePlan::Garbage;
    }
    if (busy_frames_ > 0) {
        --busy_frames_;
        return TeensyFramePlan::Busy;
    }
    if (busy_probability_ > 0.0 && next_random_busy())
        return TeensyFramePlan::Busy;
    return TeensyFramePlan::Normal;
}

bool TeensyFaults::next_random_busy() {
    // splitmix64: tiny, and the same sequence on every platform for a given seed (the
    // standard distributions are not portable).
    uint64_t z = (rng_state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    z ^= z >> 31;
    const double u = static_cast<double>(z >> 11) * 0x1.0p-53;
    return u < busy_probability_;
}

bool TeensyFaults::set_random_busy(double probability, uint64_t seed) {
    if (!(probability >= 0.0 && probability <= 1.0))
        return false;
    busy_probability_ = probability;
    rng_state_ = seed;
    return true;
}

void TeensyFaults::clear() {
    busy_frames_ = 0;
    garbage_frames_ = 0;
    no_answer_frames_ = 0;
    busy_probability_ = 0.0;
}

} // namespace caracara::sim
