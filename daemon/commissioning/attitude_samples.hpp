// The Teensy's attitude over a stretch of time, one sample per reading the Teensy gave (stamped
// with its read time, so a stalled poll leaves a gap, not its last value repeated): whether the
// vehicle holds still, and its mean attitude, yaw averaged around the circle.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

namespace caracara {

class AttitudeSamples {
public:
    using Attitude = std::array<double, 3>; // yaw, pitch, roll (rad)

    // A reading read at `t_ns`; one not after the last sample's (the same reading, looked at
    // again) is not added twice.
    void add(uint64_t t_ns, const Attitude& attitude);
    void clear() { samples_.clear(); }
    // Drops the samples older than `window_ns` before `now`.
    void keep_window(uint64_t window_ns, uint64_t now);
    // Still: the mean attitude of the last `half_ns` is within `max_rad` of the whole window's on
    // every axis (a spread test would be fooled by the sensor's noise); never while no sample is
    // older than `half_ns` (nothing of the first half to compare with), nor while none is in the
    // last `half_ns` (a stalled poll: nothing says where the vehicle is now).
    bool still(uint64_t now, uint64_t half_ns, double max_rad) const;
    // The mean attitude of the samples from `from_ns` on (none: no mean); yaw averaged as offsets
    // from the first sample so a heading near +-pi does not average to zero.
    std::optional<Attitude> mean_from(uint64_t from_ns) const;
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
