// The crash handler's claim on the I2C bus against the bus worker's thread. A fatal signal
// stops one thread; the other goes on. Without this, the worker could put a refresh of a
// running order on the wire between or after the emergency stop's zeros, and the process
// would die with that thruster running. Once the gate is closed the worker starts no
// transfer, and the handler waits (bounded) for the one already on the wire to end.
// Lock-free and async-signal-safe.
#pragma once

#include <atomic>
#include <sys/types.h>

namespace caracara {

class BusGate {
public:
    // The thread that transfers: true if it may start one (then leave() once it is over);
    // false once closed. `self` is the caller's thread id.
    bool enter(pid_t self) noexcept;
    void leave() noexcept { inside_.store(0); }

    // In the signal handler: from now on no transfer starts.
    void close() noexcept { closed_.store(true); }
    // Then: waits at most `max_wait_ms` for the transfer on the wire (not if the signal stopped
    // the transferring thread itself: it will not finish). True if the bus is the caller's alone.
    bool wait_clear(int max_wait_ms) const noexcept;
    bool closed() const noexcept { return closed_.load(); }

private:
    std::atomic<bool> closed_{false};
    std::atomic<pid_t> inside_{0}; // the thread id of the transfer on the wire, or 0
};

} // namespace caracara
