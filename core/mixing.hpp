// 6-DOF mixing: turns a motion demand on six axes into eight motor values.
//
// Motor values follow the Caracara packet seed: -8850 (full reverse) .. +8850 (full
// forward), 0 = stationary. Motor numbering matches the seed (and Scion). Per-thruster
// reversal (mounting direction) is not applied here: ThrusterDriver applies it on the wire.
//
// Axis sign conventions (the seed's axis table; the default matrix encodes exactly this):
//   x      +  towards port / left          motors 2, 6 positive; 0, 4 negative
//   y      +  forward                      motors 0, 2, 4, 6 positive
//   z      +  increase depth (down)        motors 1, 3, 5, 7 positive
//   yaw    +  clockwise viewed from above  motors 0, 2 positive; 4, 6 negative
//   pitch  +  nose up (front to the sky)   motors 3, 5 positive; 1, 7 negative
//   roll   +  clockwise viewed from behind motors 5, 7 positive; 1, 3 negative
// A negative demand is the opposite motion (starboard, backward, up, counter-clockwise,
// nose down, counter-clockwise).
#pragma once

#include "core/enum_names.hpp"
#include "core/motor.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace caracara {

inline constexpr std::size_t kAxisCount = 6;

enum class Axis : std::size_t { X = 0, Y, Z, Yaw, Pitch, Roll };

using AxisDemand = std::array<double, kAxisCount>;                  // each in -1..1
using MixMatrix = std::array<std::array<double, kAxisCount>, kMotorCount>;  // [motor][axis]

// "x", "y", "z", "yaw", "pitch", "roll"; "?" for an index out of range.
std::string_view axis_name(std::size_t axis);

// The seed's axis table as a matrix of -1 / 0 / +1.
const MixMatrix& default_mix_matrix();

enum class MixError {
    None,
    NotFinite,   // a demand (or, with a bad custom matrix, a result) is NaN or infinite
    OutOfRange,  // a demand is outside -1..1
};
template <>
struct EnumNames<MixError> {
    static constexpr std::array<EnumName<MixError>, 3> table{{
        {MixError::None, "None"},
        {MixError::NotFinite, "NotFinite"},
        {MixError::OutOfRange, "OutOfRange"},
    }};
};
inline std::string_view error_name(MixError v) { return name_of(v); }

struct MixResult {
    MixError error = MixError::None;
    int axis = -1;            // the offending axis for NotFinite/OutOfRange of a demand
    MotorValues motors{};     // all zero on error
    bool saturated = false;   // the raw mix exceeded full scale and was scaled down
    std::string message;      // human-readable, names the axis and the value
    bool ok() const { return error == MixError::None; }
};

// When the largest |value| exceeds `full`, divides every value by largest / full: one common
// factor keeps the ratios, hence the direction of motion (as ArduSub's AP_Motors6DOF does) rather
// than clipping values one by one. Returns whether it scaled.
bool saturate_keeping_direction(std::span<double> values, double full = 1.0);

// out_i = sum_j M[i][j] * demand_j. If the largest |out_i| exceeds 1, every output is
// divided by it so the direction of motion is kept (as ArduSub's AP_Motors6DOF does)
// rather than clipping motors one by one. Then scaled to kMotorMax and rounded.
MixResult mix(const AxisDemand& demand, const MixMatrix& matrix = default_mix_matrix());

} // namespace caracara
