#include "daemon/teensy/teensy_worker.hpp"

namespace caracara {

void TeensyWorker::stop() {
    thread_.stop();
    deliver();
    // What was still queued runs here, in order: a Stop of the way out is not dropped.
    std::deque<Job> rest;
    {
        std::lock_guard lk(thread_.mutex());
        rest.swap(queue_);
    }
    for (Job& j : rest)
        run_here(j);
    outstanding_ = 0;
}

void TeensyWorker::run_here(Job& job) {
    if (job.work)
        job.work();
    counters_ = link_.counters();
    if (job.done)
        job.done();
}

void TeensyWorker::submit(Work work, Done done, bool wake) {
    if (!running()) {
        Job job{std::move(work), std::move(done), wake};
        run_here(job);
        return;
    }
    ++outstanding_;
    {
        std::lock_guard lk(thread_.mutex());
        queue_.push_back({std::move(work), std::move(done), wake});
    }
    thread_.notify();
}

bool TeensyWorker::run_job(std::unique_lock<std::mutex>& lk) {
    Job job = std::move(queue_.front());
    queue_.pop_front();
    lk.unlock();
    if (job.work)
        job.work(); // nothing held
    lk.lock();
    published_ = link_.counters();
    done_.push_back(std::move(job.done));
    wake_owed_ = wake_owed_ || job.wake;
    if (!queue_.empty() || !wake_owed_)
        return false;
    wake_owed_ = false;
    return true;
}

void TeensyWorker::deliver() {
    delivering_.clear();
    {
        std::lock_guard lk(thread_.mutex());
        delivering_.swap(done_);
        wake_owed_ = false;
        if (!delivering_.empty())
            counters_ = published_;
    }
    for (Done& d : delivering_) {
        --outstanding_;
        if (d)
            d();
    }
    delivering_.clear();
}

} // namespace caracara
