#include "daemon/commissioning/attitude_samples.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace caracara {

namespace {

double wrap(double a) {
    double r = std::remainder(a, 2.0 * std::numbers::pi);
    return r <= -std::numbers::pi ? r + 2.0 * std::numbers::pi : r;
}

} // namespace

void AttitudeSamples::add(uint64_t t_ns, const Attitude& attitude) {
    if (samples_.empty() || t_ns > samples_.back().t_ns)
        samples_.push_back({t_ns, attitude});
}

void AttitudeSamples::keep_window(uint64_t window_ns, uint64_t now) {
    std::erase_if(samples_, [&](const Sample& s) { return s.t_ns + window_ns < now; });
}

bool AttitudeSamples::still(uint64_t now, uint64_t half_ns, double max_rad) const {
    // Two halves to compare: a late step (a loaded machine) leaves the window its last half only,
    // or one sample, whose mean is trivially the whole window's.
    if (samples_.empty() || samples_.front().t_ns + half_ns > now)
        return false;
    const std::optional<Attitude> last_half = mean_from(now - half_ns);
    if (!last_half)
        return false;
    const Attitude moved = change(*mean_from(0), *last_half);
    double worst = 0.0;
    for (const double m : moved)
        worst = std::max(worst, std::abs(m));
    return worst <= max_rad;
}

std::optional<AttitudeSamples::Attitude> AttitudeSamples::mean_from(uint64_t from_ns) const {
    Attitude sum{};
    std::size_t n = 0;
    double ref = 0.0;
    for (const Sample& s : samples_) {
        if (s.t_ns < from_ns)
            continue;
        if (n == 0)
            ref = s.att[0];
        sum[0] += wrap(s.att[0] - ref);
        sum[1] += s.att[1];
        sum[2] += s.att[2];
        ++n;
    }
    if (n == 0)
        return std::nullopt;
    return Attitude{wrap(ref + sum[0] / double(n)), sum[1] / double(n), sum[2] / double(n)};
}

AttitudeSamples::Attitude AttitudeSamples::change(const Attitude& before, const Attitude& after) {
    return {wrap(after[0] - before[0]), after[1] - before[1], after[2] - before[2]};
}

} // namespace caracara
