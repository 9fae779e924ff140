// Bus work that is not a thruster's order or status read (a bus scan's probes): the BusWorker
// runs each step on its thread, behind every order queued, and a kill's zeros drop a step still
// waiting, as they drop everything queued (dropped() says so).
#pragma once

#include "daemon/bus/bus_job_queue.hpp"
#include "drivers/platform/io_error.hpp"

#include <cstdint>

namespace caracara {

class BusProber {
public:
    // On the bus worker's thread: step `step`'s transfers.
    virtual IoError probe(uint32_t step) = 0;
    // On the loop thread: the step is over (or was skipped).
    virtual void probed(const BusJobDone& done) = 0;
    // On the loop thread: what was queued was dropped (a kill's zeros, a bus recovery); a step
    // on the wire still comes back through probed().
    virtual void dropped() = 0;

protected:
    ~BusProber() = default;
};

} // namespace caracara
