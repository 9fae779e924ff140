#include "daemon/bus/bus_job_queue.hpp"

#include <algorithm>

namespace caracara {

std::size_t BusJobQueue::push(const BusJob& job, bool replace) {
    const auto first = jobs_.begin() + static_cast<std::ptrdiff_t>(head_);
    if (job.kind != BusJobKind::Order) {
        jobs_.push_back(job);
        return 0;
    }
    const auto is_order = [](const BusJob& j) { return j.kind == BusJobKind::Order; };
    if (replace) {
        // The last one queued for the thruster, in its place: the newer value goes out as soon
        // as the older one would have (an earlier one, before zeros queued behind, stays).
        const auto same = std::find_if(jobs_.rbegin(), std::make_reverse_iterator(first),
                                       [&](const BusJob& j) { return is_order(j) && j.index == job.index; });
        if (same != std::make_reverse_iterator(first)) {
            *same = job;
            return 1;
        }
    }
    jobs_.insert(std::find_if_not(first, jobs_.end(), is_order), job);
    return 0;
}

std::size_t BusJobQueue::replace_all(std::span<const BusJob> jobs, uint64_t epoch) {
    const std::size_t dropped = clear();
    for (BusJob j : jobs) {
        j.epoch = epoch;
        jobs_.push_back(j);
    }
    return dropped;
}

std::size_t BusJobQueue::clear() {
    const std::size_t n = jobs_.size() - head_;
    jobs_.clear();
    head_ = 0;
    return n;
}

BusJob BusJobQueue::pop() {
    const BusJob job = jobs_[head_++];
    if (head_ == jobs_.size())
        clear();
    return job;
}

} // namespace caracara
