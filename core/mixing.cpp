#include "core/mixing.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace caracara {

std::string_view axis_name(std::size_t axis) {
    static constexpr std::array<std::string_view, kAxisCount> names{"x", "y", "z", "yaw", "pitch", "roll"};
    return axis < names.size() ? names[axis] : std::string_view("?");
}

const MixMatrix& default_mix_matrix() {
    //                                         x     y     z    yaw  pitch roll
    static const MixMatrix m{{
        /* motor 0 */ std::array<double, 6>{-1.0, +1.0, 0.0, +1.0, 0.0, 0.0},
        /* motor 1 */ std::array<double, 6>{0.0, 0.0, +1.0, 0.0, -1.0, -1.0},
        /* motor 2 */ std::array<double, 6>{+1.0, +1.0, 0.0, +1.0, 0.0, 0.0},
        /* motor 3 */ std::array<double, 6>{0.0, 0.0, +1.0, 0.0, +1.0, -1.0},
        /* motor 4 */ std::array<double, 6>{-1.0, +1.0, 0.0, -1.0, 0.0, 0.0},
        /* motor 5 */ std::array<double, 6>{0.0, 0.0, +1.0, 0.0, +1.0, +1.0},
        /* motor 6 */ std::array<double, 6>{+1.0, +1.0, 0.0, -1.0, 0.0, 0.0},
        /* motor 7 */ std::array<double, 6>{0.0, 0.0, +1.0, 0.0, -1.0, +1.0},
    }};
    return m;
}

namespace {
MixResult mix_error(MixError e, int axis, std::string message) {
    MixResult r;
    r.error = e;
    r.axis = axis;
    r.message = std::move(message);
    return r;
}
} // namespace

bool saturate_keeping_direction(std::span<double> values, double full) {
    double peak = 0.0;
    for (double v : values)
        peak = std::max(peak, std::abs(v));
    if (peak <= full)
        return false;
    for (double& v : values)
        v *= full / peak;
    return true;
}

MixResult mix(const AxisDemand& demand, const MixMatrix& matrix) {
    for (std::size_t j = 0; j < kAxisCount; ++j) {
        const double a = demand[j];
        std::ostringstream os;
        os << axis_name(j) << ": ";
        if (!std::isfinite(a)) {
            os << "must be a finite number, got " << a;
            return mix_error(MixError::NotFinite, static_cast<int>(j), os.str());
        }
        if (a < -1.0 || a > 1.0) {
            os << "must be between -1 and 1, got " << a;
            return mix_error(MixError::OutOfRange, static_cast<int>(j), os.str());
        }
    }

    std::array<double, kMotorCount> out{};
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        double sum = 0.0;
        for (std::size_t j = 0; j < kAxisCount; ++j)
            sum += matrix[i][j] * demand[j];
        if (!std::isfinite(sum))
            return mix_error(MixError::NotFinite, -1,
                             "motor " + std::to_string(i) + ": the mixing matrix produced a non-finite value");
        out[i] = sum;
    }

    MixResult r;
    r.saturated = saturate_keeping_direction(out);
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        const double v = std::clamp(out[i], -1.0, 1.0) * kMotorMax;
        r.motors[i] = static_cast<int32_t>(std::lround(v));
    }
    return r;
}

} // namespace caracara
