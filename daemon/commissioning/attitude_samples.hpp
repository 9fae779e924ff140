// The Teensy's attitude over a stretch of time, as direction detection samples it each step:
// whether the vehicle holds still, and its mean attitude, yaw averaged around the circle.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace caracara {

class AttitudeSamples {
public:
    using Attitude = std::array<double, 3>; // yaw, pitch, roll (rad)

    void add(uint64_t t_ns, const Attitude& attitude) { samples_.push_back({t_ns, attitude}); }
    void clear() { samples_.clear(); }
    // Drops the samples older than `window_ns` before `now`.
    void keep_window(uint64_t window_ns, uint64_t now);
    // Still: the mean attitude of the last `half_ns` is within `max_rad` of the whole window's on
    // every axis (a spread test would be fooled by the sensor's noise); never while no sample is
    // older than `half_ns` (nothing of the first half to compare with).
    bool still(uint64_t now, uint64_t half_ns, double max_rad) const;
    // The mean attitude of the samples from `from_ns` on; yaw averaged as offsets from the first
    // sample so a heading near +-pi does not average to zero.
    Attitude mean_from(uint64_t from_ns) const;
    // after - before on each axis, yaw wrapped to (-pi, pi].
    static Attitude change(const Attitude& before, const Attitude& after);

private:
    struct Sample {
        uint64_t t_ns;
        Attitude att;
    };
    std::vector<Sample> samples_;
};

} // namespace caracara
