#include "core/direction_judgement.hpp"

#include "core/hex.hpp"

#include <cmath>

namespace caracara {

DirectionJudgement judge_direction(const MixMatrix& mixing, std::size_t motor, int32_t pulse_value,
                                   const std::array<double, 3>& change, double threshold_rad) {
    DirectionJudgement j;
    if (motor >= kMotorCount || pulse_value == 0 || !(threshold_rad > 0.0))
        return j;
    const auto& row = mixing[motor];
    const double sign = pulse_value > 0 ? 1.0 : -1.0;
    const std::array<double, 3> expected = {sign * row[static_cast<std::size_t>(Axis::Yaw)],
                                            sign * row[static_cast<std::size_t>(Axis::Pitch)],
                                            sign * row[static_cast<std::size_t>(Axis::Roll)]};
    double norm = 0.0;
    for (double e : expected)
        norm += e * e;
    norm = std::sqrt(norm);
    if (norm == 0.0)
        return j; // the mixing gives it no rotation: a pulse cannot tell
    double along = 0.0;
    for (std::size_t k = 0; k < 3; ++k)
        along += change[k] * expected[k] / norm;
    double across = 0.0;
    for (std::size_t k = 0; k < 3; ++k) {
        const double d = change[k] - along * expected[k] / norm;
        across += d * d;
    }
    across = std::sqrt(across);
    j.along = along;
    j.margin = std::abs(along) / threshold_rad;
    if (!std::isfinite(along) || std::abs(along) < threshold_rad || across > std::abs(along))
        return j;
    j.verdict = along > 0.0 ? DirectionVerdict::Ok : DirectionVerdict::Reversed;
    return j;
}

std::string reversal_fragment(const std::array<ThrusterConfig, kMotorCount>& thrusters,
                              const std::array<DirectionJudgement, kMotorCount>& found) {
    std::string out = "# Thruster directions found by caracaractl detect-directions: replace the [[thruster]]\n"
                      "# tables of caracarad.toml with these, then restart caracarad.\n";
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        const ThrusterConfig& t = thrusters[i];
        const DirectionJudgement& j = found[i];
        const bool reversed = j.verdict == DirectionVerdict::Reversed ? !t.reversed : t.reversed;
        out += "\n[[thruster]] # motor " + std::to_string(i) + ": " + std::string(verdict_name(j.verdict));
        if (j.verdict == DirectionVerdict::Inconclusive)
            out += ", kept as configured: check it by hand";
        out += "\naddress = " + hex(t.mt) + "\nvariant = \"" + std::string(variant_name(t.variant)) + "\"\n";
        if (t.info != kDefaultInfo)
            out += "info = " + std::to_string(t.info) + "\n";
        if (t.mux)
            out += "mux_address = " + hex(t.mux->addr7) + "\nmux_channel = " + std::to_string(t.mux->channel) + "\n";
        out += std::string("reversed = ") + (reversed ? "true" : "false") + "\n";
    }
    return out;
}

} // namespace caracara
