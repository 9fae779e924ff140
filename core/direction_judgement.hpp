// Thruster direction detection's decision (docs/commissioning.md; after ArduSub's motor
// detection, on our mixing): a thruster pulsed alone turns the vehicle; the change of yaw,
// pitch and roll it caused is compared with what the mixing matrix says that thruster does.
// Pure: the daemon (daemon/commissioning/direction_detection) pulses and measures.
#pragma once

#include "core/enum_names.hpp"
#include "core/mixing.hpp"
#include "core/thruster_config.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace caracara {

enum class DirectionVerdict : uint8_t { Ok, Reversed, Inconclusive };
template <>
struct EnumNames<DirectionVerdict> {
    static constexpr std::array<EnumName<DirectionVerdict>, 3> table{{
        {DirectionVerdict::Ok, "ok"},
        {DirectionVerdict::Reversed, "reversed"},
        {DirectionVerdict::Inconclusive, "inconclusive"},
    }};
};
inline std::string_view verdict_name(DirectionVerdict v) { return name_of(v); }

struct DirectionJudgement {
    DirectionVerdict verdict = DirectionVerdict::Inconclusive;
    // The measured change (rad) along the rotation the mixing expects: > 0 the way it expects.
    double along = 0.0;
    // |along| / the threshold: how far the finding is from "too small to tell" (>= 1 decided).
    double margin = 0.0;
};

// `change`: yaw, pitch, roll after the pulse minus before it (rad); `pulse_value` the motor value
// ordered (its sign matters); `threshold_rad` the smallest change believed. Inconclusive when the
// thruster has no rotation in the mixing, when the change along it is under the threshold, or
// when the vehicle turned more across the expected rotation than along it.
DirectionJudgement judge_direction(const MixMatrix& mixing, std::size_t motor, int32_t pulse_value,
                                   const std::array<double, 3>& change, double threshold_rad);

// The [[thruster]] tables to apply: each as configured, `reversed` flipped for a thruster found
// reversed; an inconclusive one kept and marked with a comment. Never applied by the daemon.
std::string reversal_fragment(const std::array<ThrusterConfig, kMotorCount>& thrusters,
                              const std::array<DirectionJudgement, kMotorCount>& found);

} // namespace caracara
