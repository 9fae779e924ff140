#include "daemon/bus/bus_transfer.hpp"

#include <unistd.h>

namespace caracara {

BusJobDone BusTransfer::run(const BusJob& job) {
    // A non-zero order from before the last kill is dropped here, at the last moment.
    if (job.kind == BusJobKind::Order && job.value != 0 && job.epoch != epoch_.load())
        return {job, IoError::None, true};
    BusGate* gate = gate_.load();
    // The thread's id, taken once: gettid() is a system call, and this runs for every transfer.
    thread_local const pid_t self = ::gettid();
    if (gate && !gate->enter(self))
        return {job, IoError::None, true}; // the crash handler has the bus; the process is ending
    const IoError e = job.kind == BusJobKind::Probe   ? prober_->probe(static_cast<uint32_t>(job.value))
                      : job.kind == BusJobKind::Order ? drivers_[job.index]->send_order(job.value)
                                                      : drivers_[job.index]->read_status();
    if (gate)
        gate->leave();
    return {job, e, false};
}

} // namespace caracara
