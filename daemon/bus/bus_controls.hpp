// The bus worker's own controls, as ThrusterBus::worker() hands them out: how the transfers
// handed over wake its thread and come back to the loop, a kill's fence, the emergency stop's
// gate, and whether it is idle. Handing it work (orders, status reads, probes) is the
// ThrusterBus's alone, which keeps what was ordered; BusWorker implements these.
#pragma once

#include "drivers/devices/bus_gate.hpp"

namespace caracara {

class BusControls {
public:
    // The thread is woken once for the jobs handed over between these two (a dispatch of the
    // cycle's work), not at each.
    virtual void hold_wakeups() = 0;
    virtual void release_wakeups() = 0;
    // Before a kill's kill output: no non-zero order handed over earlier goes out after it.
    virtual void hold_orders() = 0;
    // The emergency stop's gate: see BusTransfer::set_gate.
    virtual void set_gate(BusGate* gate) = 0;
    // Nothing queued, on the wire, or finished but not yet handed back.
    virtual bool idle() const = 0;
    // The jobs handed over so far come back at once, whatever ThrusterBus::set_results_at_tick says.
    virtual void wake_when_done() = 0;
    // The loop takes the finished jobs' results now (at its tick).
    virtual void collect() = 0;
    // Blocks until idle: start-up and shutdown, where the zeros must be on the wire first.
    virtual void wait_idle() = 0;

protected:
    ~BusControls() = default;
};

} // namespace caracara
