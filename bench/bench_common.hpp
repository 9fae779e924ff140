// Small helpers shared by the benchmark programs: the monotonic clock, percentiles, JSON.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

namespace caracara::bench {

inline uint64_t mono_ns() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<uint64_t>(ts.tv_sec) * 1'000'000'000ull + static_cast<uint64_t>(ts.tv_nsec);
}

inline void sleep_ns(uint64_t ns) {
    timespec ts{static_cast<time_t>(ns / 1'000'000'000ull), static_cast<long>(ns % 1'000'000'000ull)};
    while (clock_nanosleep(CLOCK_MONOTONIC, 0, &ts, &ts) != 0) {
    }
}

inline void sleep_until_ns(uint64_t at) {
    timespec ts{static_cast<time_t>(at / 1'000'000'000ull), static_cast<long>(at % 1'000'000'000ull)};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
    }
}

// Nearest-rank percentile of an unsorted sample (copied and sorted).
inline double percentile(std::vector<double> v, double p) {
    if (v.empty())
        return std::nan("");
    std::sort(v.begin(), v.end());
    const double rank = std::ceil(p / 100.0 * static_cast<double>(v.size()));
    const size_t i = rank < 1 ? 0 : static_cast<size_t>(rank) - 1;
    return v[std::min(i, v.size() - 1)];
}

inline double mean(const std::vector<double>& v) {
    if (v.empty())
        return std::nan("");
    double s = 0;
    for (double x : v)
        s += x;
    return s / static_cast<double>(v.size());
}

// {"n":..,"p50":..,"p90":..,"p99":..,"max":..,"mean":..,"min":..} of `v`.
inline std::string stats_json(const std::vector<double>& v) {
    char buf[256];
    const auto num = [](double x) { return std::isnan(x) ? 0.0 : x; };
    std::snprintf(buf, sizeof buf,
                  "{\"n\": %zu, \"min\": %.3f, \"p50\": %.3f, \"p90\": %.3f, \"p99\": %.3f, \"max\": %.3f, \"mean\": %.3f}",
                  v.size(), num(v.empty() ? 0 : *std::min_element(v.begin(), v.end())), num(percentile(v, 50)),
                  num(percentile(v, 90)), num(percentile(v, 99)),
                  num(v.empty() ? 0 : *std::max_element(v.begin(), v.end())), num(mean(v)));
    return buf;
}

// [x, y, ...] with 1 decimal, for merging raw samples across runs.
inline std::string array_json(const std::vector<double>& v) {
    std::string s = "[";
    char buf[32];
    for (size_t i = 0; i < v.size(); ++i) {
        std::snprintf(buf, sizeof buf, i ? ", %.1f" : "%.1f", v[i]);
        s += buf;
    }
    return s + "]";
}

// A tiny deterministic PRNG (xorshift64*), so runs are repeatable.
class Rng {
public:
    explicit Rng(uint64_t seed) : s_(seed ? seed : 0x9E3779B97F4A7C15ull) {}
    uint64_t next() {
        s_ ^= s_ >> 12;
        s_ ^= s_ << 25;
        s_ ^= s_ >> 27;
        return s_ * 0x2545F4914F6CDD1Dull;
    }
    // Uniform in [0, n).
    uint64_t below(uint64_t n) { return n ? next() % n : 0; }

private:
    uint64_t s_;
};

} // namespace caracara::bench
