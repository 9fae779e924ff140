#include "core/force_curve.hpp"

#include <algorithm>
#include <cmath>

namespace caracara {

namespace {
// Linear interpolation along points at evenly spaced x 0..1.
double along(const std::vector<double>& p, double x) {
    const double at = std::clamp(x, 0.0, 1.0) * static_cast<double>(p.size() - 1);
    const std::size_t i = std::min(static_cast<std::size_t>(at), p.size() - 2);
    return p[i] + (p[i + 1] - p[i]) * (at - static_cast<double>(i));
}

// The inverse of along(): the x at which it gives y (0 <= y <= p.back()).
double inverse(const std::vector<double>& p, double y) {
    const double n = static_cast<double>(p.size() - 1);
    for (std::size_t i = 0; i + 1 < p.size(); ++i)
        if (y <= p[i + 1])
            return (static_cast<double>(i) + (y - p[i]) / (p[i + 1] - p[i])) / n;
    return 1.0;
}
} // namespace

ForceCurve::ForceCurve() : ForceCurve({0.0, kBtd150ForwardN}, {0.0, kBtd150ReverseN}) {}

ForceCurve::ForceCurve(std::vector<double> forward_n, std::vector<double> reverse_n)
    : forward_n_(std::move(forward_n)), reverse_n_(std::move(reverse_n)) {}

std::string ForceCurve::check(const std::vector<double>& p) {
    if (p.size() < 2)
        return "must list at least 2 thrusts in newtons (at 0 and at full demand)";
    if (p[0] != 0.0)
        return "must start at 0 (no thrust at motor value 0)";
    for (std::size_t i = 1; i < p.size(); ++i)
        if (!std::isfinite(p[i]) || p[i] <= p[i - 1])
            return "must rise strictly (each thrust above the one before, finite), so each force has one motor value";
    return "";
}

double ForceCurve::full_n(bool reverse) const { return reverse ? reverse_n_.back() : forward_n_.back(); }

double ForceCurve::force_n(double fraction) const {
    return fraction < 0 ? -along(reverse_n_, -fraction) : along(forward_n_, fraction);
}

double ForceCurve::fraction(double force_n) const {
    return force_n < 0 ? -inverse(reverse_n_, -force_n) : inverse(forward_n_, force_n);
}

} // namespace caracara
