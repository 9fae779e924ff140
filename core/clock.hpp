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

} // namespace caracara
