// One bus job's transfer, on the BusWorker's thread, with the two things that may keep it off
// the wire at the last moment: a kill since it was handed over (a non-zero order from before
// the kill is not sent) and the emergency stop's gate (a crash handler sending its zeros).
#pragma once

#include "daemon/bus/bus_job_queue.hpp"
#include "daemon/bus/bus_prober.hpp"
#include "drivers/devices/bus_gate.hpp"
#include "drivers/devices/thruster_driver.hpp"

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

namespace caracara {

class BusTransfer {
public:
    explicit BusTransfer(std::vector<std::unique_ptr<ThrusterDriver>>& drivers) : drivers_(drivers) {}

    // How many times hold_orders() was called: a job carries it from when it was handed over.
    uint64_t epoch() const { return epoch_.load(); }
    // From now on, a non-zero order handed over before this call is not sent: a kill calls it
    // before it writes the kill output, so no such order can follow the kill output onto the
    // wire once the worker has seen it (at most the one whose transfer had already begun).
    void hold_orders() { epoch_.fetch_add(1); }
    // Every transfer enters `gate` (the emergency stop's), so a crash handler on another thread
    // can keep this one off the wire while it sends its zeros. Null: no gate.
    void set_gate(BusGate* gate) { gate_.store(gate); }
    void set_prober(BusProber* prober) { prober_ = prober; } // runs the Probe jobs; set while idle

    // The job's transfer, unless a kill overtook it or the gate is closed (`skipped`).
    BusJobDone run(const BusJob& job);

private:
    std::vector<std::unique_ptr<ThrusterDriver>>& drivers_; // the worker's thread's while it runs
    std::atomic<uint64_t> epoch_{0};
    std::atomic<BusGate*> gate_{nullptr};
    BusProber* prober_ = nullptr;
};

} // namespace caracara
