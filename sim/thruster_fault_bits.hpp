// The simulated thruster's (sim/thruster_model) fault bits and their names (caracara-sim's
// inspection API: SetFault takes a name, Faults lists them).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace caracara::sim {

// Fault bits in the SeaBotix FAULT byte order; the legacy STATUS byte uses bits 0-3 the
// same way and bit 4 for water detect.
enum FaultBit : uint8_t {
    kOvertemp = 1 << 0,
    kStall = 1 << 1,
    kHall = 1 << 2,
    kGroundFault = 1 << 3,
    kWaterDetect = 1 << 4,
};
std::optional<uint8_t> fault_bit_from_name(const std::string& name);
std::vector<std::string> fault_names(uint8_t bits);

} // namespace caracara::sim
