// A surface failsafe carried out: the ascent ([failsafe.surface]: a heave demand, re-sent at
// every reading so the command timeout does not stop it) for its time, then a kill; a kill
// that comes first ends it. Owned by the FailsafeMonitor.
#pragma once

#include "core/failsafe.hpp"
#include "daemon/vehicle/vehicle.hpp"
#include "daemon/interfaces/vehicle_events.hpp"

#include <cstdint>
#include <string>

namespace caracara {

class FailsafeAscent final {
public:
    FailsafeAscent(const SurfaceSettings& settings, Vehicle& vehicle, VehicleEvents& events)
        : settings_(settings), vehicle_(vehicle), events_(events) {}
    bool active() const { return until_ != 0; }
    // When the running ascent ends with its kill (CLOCK_MONOTONIC ns); 0 when none runs.
    uint64_t until() const { return until_; }
    // Starts the ascent, or kills (with `reason`) when the vehicle cannot drive it.
    void begin(std::string reason, uint64_t now);
    // At each reading: the ascent again, its kill once its time is up, or its end by a kill.
    void keep(uint64_t now);

private:
    const SurfaceSettings& settings_;
    Vehicle& vehicle_;
    VehicleEvents& events_;
    uint64_t until_ = 0; // 0: not surfacing
    std::string reason_;
};

} // namespace caracara
