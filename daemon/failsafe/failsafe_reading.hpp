// A thruster's last good status reply, as the failsafe policy reads it (the VehicleDaemon
// makes it from the thruster's last status; the FailsafeMonitor reads one per thruster).
#pragma once

#include <cstdint>
#include <optional>

namespace caracara {

struct FailsafeReading {
    uint8_t fault_bits = 0;                // SeaBotix IDS 8.4.2 FAULT bit order
    std::optional<uint8_t> temperature_c;  // SeaBotix controllers only

    bool operator==(const FailsafeReading&) const = default;
};

} // namespace caracara
