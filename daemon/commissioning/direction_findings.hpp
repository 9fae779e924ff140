// What a direction detection run found, thruster by thruster: each pulse's attitude change
// judged by core/direction_judgement against the mixing, and the [[thruster]] fragment with the
// reversal flags found (the caller's to apply; caracarad never changes its configuration).
#pragma once

#include "core/config.hpp"
#include "core/direction_judgement.hpp"

#include <array>
#include <cstddef>
#include <string>

namespace caracara {

// One thruster's finding: the judgement and the attitude change (yaw, pitch, roll, rad) it is on.
struct DirectionFinding {
    DirectionJudgement judgement;
    std::array<double, 3> change{};
};

class DirectionFindings {
public:
    explicit DirectionFindings(const DaemonConfig& config) : config_(config) {}

    void clear() { findings_ = {}; }
    // Thruster `motor`'s pulse (commissioning.detect_pulse_value) turned the vehicle by `change`:
    // judged with commissioning.detect_threshold_mrad, and logged.
    void record(std::size_t motor, const std::array<double, 3>& change);
    const std::array<DirectionFinding, kMotorCount>& all() const { return findings_; }
    std::string fragment() const;

private:
    const DaemonConfig& config_;
    std::array<DirectionFinding, kMotorCount> findings_{};
};

} // namespace caracara
