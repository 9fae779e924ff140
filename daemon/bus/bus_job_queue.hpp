// The queue of I2C jobs waiting for the BusWorker's thread, and its order: orders go before
// the status reads, a newer order for a thruster takes the place of one still queued for it
// (a new command waits at most for the transfer on the wire), and a kill's zero orders
// replace everything queued. Not thread-safe: the BusWorker holds its lock around each call.
// A vector read from `head_`: the queue holds a cycle's work (a dozen jobs) and runs dry at
// every cycle, so it allocates only when it first grows.
#pragma once

#include "core/zero_order.hpp"
#include "drivers/platform/io_error.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>
#include <span>

namespace caracara {

// Probe: a bus scan's step (BusProber; index 0, value the step), queued as a status read is:
// behind every order, and dropped by a kill's zeros as they are.
// Probe: a bus scan's step (BusProber; index 0, value the step), queued as a status read is:
// behind every order, and dropped by a kill's zeros as everything queued is.
enum class BusJobKind : uint8_t { Order, Status, Probe };

struct BusJob {
    BusJobKind kind = BusJobKind::Order;
    uint32_t index = 0;
    int32_t value = 0;  // the motor value of an order; a probe's step
    uint64_t epoch = 0; // hold_orders() count when it was handed over (set by submit)
};

struct BusJobDone {
    BusJob job;
    IoError error = IoError::None;
    bool skipped = false; // a non-zero order that a kill overtook: never sent
};

class BusJobQueue {
public:
    // Queues `job` in its place; returns how many queued jobs it replaced (0 or 1).
    std::size_t push(const BusJob& job, bool replace);
    // `jobs` replace everything queued, each stamped with `epoch`; returns how many were dropped.
    std::size_t replace_all(std::span<const BusJob> jobs, uint64_t epoch);
    // Drops everything queued; returns how many.
    std::size_t clear();
    BusJob pop();
    bool empty() const { return head_ == jobs_.size(); }

private:
    std::vector<BusJob> jobs_; // queued: [head_, end)
    std::size_t head_ = 0;
};

} // namespace caracara
