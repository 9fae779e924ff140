// One sample of the whole vehicle for the dive recorder (docs/dive-format.md): motor values
// requested and applied, the budget, the vehicle's flags, each thruster's status and counters,
// the Teensy's orientation and distances, the bus counters. Read on the loop, no system call.
#pragma once

#include "core/dive_format.hpp"
#include "daemon/bus/thruster_bus.hpp"
#include "daemon/teensy/teensy_port.hpp"
#include "daemon/vehicle/vehicle.hpp"

#include <cstdint>

namespace caracara {

class DiveSampler {
public:
    DiveSampler(const Vehicle& vehicle, const ThrusterBus& bus, const TeensyPort& teensy)
        : vehicle_(vehicle), bus_(bus), teensy_(teensy) {}
    // `t_100us`: the time since the dive began, in 100 us. Filled in place, valid until the
    // next call: one sample a cycle, and no allocation for it (its distances keep their room).
    const dive::Sample& sample(uint32_t t_100us);

private:
    const Vehicle& vehicle_;
    const ThrusterBus& bus_;
    const TeensyPort& teensy_;
    dive::Sample sample_;
};

} // namespace caracara
