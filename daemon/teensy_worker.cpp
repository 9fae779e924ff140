#include "daemon/teensy_worker.hpp"

namespace caracara {

std::string TeensyWorker::start(sd_event* event, int64_t priority) {
    if (running())
        return {};
    if (std::string e = waker_.open(event, priority, [this] { deliver(); }); !e.empty())
        return e;
    stopping_ = false;
    // Signals stay blocked in this thread as in the one that made it (see BusWorker::start).
    thread_ = std::thread([this] { run(); });
    return {};
}

void TeensyWorker::stop() {
    if (running()) {
        {
            std::lock_guard lk(mu_);
            stopping_ = true;
        }
        wake_.notify_all();
        thread_.join();
    }
    deliver();
    // What was still queued runs here, in order: a Stop of the way out is not dropped.
    std::deque<Job> rest;
    {
        std::lock_guard lk(mu_);
        rest.swap(queue_);
    }
    for (Job& j : rest) {
        if (j.work)
            j.work();
        counters_ = link_.counters();
        if (j.done)
            j.done();
    }
    outstanding_ = 0;
    waker_.close();
}

void TeensyWorker::submit(Work work, Done done, bool wake) {
    if (!running()) {
        if (work)
            work();
        counters_ = link_.counters();
        if (done)
            done();
        return;
    }
    ++outstanding_;
    {
        std::lock_guard lk(mu_);
        queue_.push_back({std::move(work), std::move(done), wake});
    }
    wake_.notify_one();
}

void TeensyWorker::run() {
    std::unique_lock lk(mu_);
    for (;;) {
        wake_.wait(lk, [this] { return stopping_ || !queue_.empty(); });
        if (stopping_)
            return;
        Job job = std::move(queue_.front());
        queue_.pop_front();
        lk.unlock();
        if (job.work)
            job.work(); // nothing held
        lk.lock();
        published_ = link_.counters();
        done_.push_back(std::move(job.done));
        wake_owed_ = wake_owed_ || job.wake;
        if (queue_.empty() && wake_owed_) {
            wake_owed_ = false;
            waker_.wake();
        }
    }
}

void TeensyWorker::deliver() {
    delivering_.clear();
    {
        std::lock_guard lk(mu_);
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
