#include "daemon/commissioning/direction_findings.hpp"

#include "daemon/loop/log.hpp"

namespace caracara {

void DirectionFindings::record(std::size_t motor, const std::array<double, 3>& change) {
    const auto& c = config_.commissioning;
    DirectionFinding& f = findings_[motor];
    f.change = change;
    f.judgement = judge_direction(config_.mixing, motor, c.detect_pulse_value, f.change, c.detect_threshold_mrad / 1000.0);
    log_notice("direction detection: thruster %zu %s (yaw %+.4f pitch %+.4f roll %+.4f rad, margin %.1f)", motor,
               std::string(verdict_name(f.judgement.verdict)).c_str(), f.change[0], f.change[1], f.change[2],
               f.judgement.margin);
}

std::string DirectionFindings::fragment() const {
    std::array<DirectionJudgement, kMotorCount> j{};
    for (std::size_t i = 0; i < kMotorCount; ++i)
        j[i] = findings_[i].judgement;
    return reversal_fragment(config_.thrusters, j);
}

} // namespace caracara
