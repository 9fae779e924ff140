// Physics step for models that evolve in time (thruster ramp and heat, vehicle attitude).
#pragma once

#include <cstdint>

namespace caracara::sim {

class Stepped {
public:
    virtual ~Stepped() = default;
    virtual void step(double dt_s, uint64_t now_ns) = 0;
};

} // namespace caracara::sim
