#include "sim/thruster_fault_bits.hpp"

#include <array>
#include <utility>

namespace caracara::sim {

namespace {
const std::array<std::pair<uint8_t, const char*>, 5> kFaultNames = {{
    {kOvertemp, "overtemp"},
    {kStall, "stall"},
    {kHall, "hall"},
    {kGroundFault, "ground-fault"},
    {kWaterDetect, "water-detect"},
}};
} // namespace

std::optional<uint8_t> fault_bit_from_name(const std::string& name) {
    for (auto& [bit, n] : kFaultNames)
        if (name == n)
            return bit;
    return std::nullopt;
}

std::vector<std::string> fault_names(uint8_t bits) {
    std::vector<std::string> out;
    for (auto& [bit, n] : kFaultNames)
        if (bits & bit)
            out.emplace_back(n);
    return out;
}

} // namespace caracara::sim
