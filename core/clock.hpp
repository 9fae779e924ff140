// CLOCK_MONOTONIC in nanoseconds: the one time base of the daemon, the simulator's wire log
// and the tests. Pure logic takes the time as an argument; only the callers read the clock.
#pragma once

#include <cstdint>
#include <ctime>

namespace caracara {

inline uint64_t monotonic_ns() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<uint64_t>(ts.tv_sec) * 1'000'000'000ull + static_cast<uint64_t>(ts.tv_nsec);
}

// The time from `since` to `now`, 0 when `since` is the later: a monotonic clock never goes
// back, but a time taken before another (a timer's due time, a caller's stale timestamp) must
// not wrap round into a huge age (ending arming, or starving systemd's watchdog, early).
constexpr uint64_t elapsed(uint64_t since, uint64_t now) { return now > since ? now - since : 0; }

} // namespace caracara
