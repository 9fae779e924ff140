#include "daemon/bus_job_queue.hpp"

#include <algorithm>

namespace caracara {

std::size_t BusJobQueue::push(const BusJob& job, bool replace) {
    if (job.kind != BusJobKind::Order) {
        queue_.push_back(job);
        return 0;
    }
    std::size_t replaced = 0;
    for (auto it = queue_.begin(); replace && it != queue_.end(); ++it)
        if (it->kind == BusJobKind::Order && it->index == job.index) {
            queue_.erase(it);
            replaced = 1;
            break;
        }
    auto pos = std::find_if(queue_.begin(), queue_.end(), [](const BusJob& j) { return j.kind != BusJobKind::Order; });
    queue_.insert(pos, job);
    return replaced;
}

std::size_t BusJobQueue::replace_all(std::span<const BusJob> jobs, uint64_t epoch) {
    const std::size_t dropped = clear();
    for (BusJob j : jobs) {
        j.epoch = epoch;
        queue_.push_back(j);
    }
    return dropped;
}

std::size_t BusJobQueue::clear() {
    const std::size_t n = queue_.size();
    queue_.clear();
    return n;
}

BusJob BusJobQueue::pop() {
    const BusJob job = queue_.front();
    queue_.pop_front();
    return job;
}

} // namespace caracara
