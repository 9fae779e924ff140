// Motor values as the Caracara packet seed defines them: eight motors, -8850 (full reverse)
// .. +8850 (full forward), 0 stationary. One definition for mixing, the budget, the packet
// decoder and the thruster codec.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace caracara {

inline constexpr std::size_t kMotorCount = 8;
inline constexpr int32_t kMotorMax = 8850; // full thrust either way
using MotorValues = std::array<int32_t, kMotorCount>;

} // namespace caracara
