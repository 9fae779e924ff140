#include "daemon/bus/bus_worker.hpp"

#include <unistd.h>

namespace caracara {

namespace {
constexpr std::size_t kWakeEvery = 16;
} // namespace

BusWorker::BusWorker(std::vector<std::unique_ptr<ThrusterDriver>>& drivers) : drivers_(drivers) {
    for (const auto& d : drivers_) {
        views_.push_back(*d);
        published_.push_back(*d);
    }
    done_.reserve(kWakeEvery * 2);
    delivering_.reserve(kWakeEvery * 2);
}

std::string BusWorker::start(sd_event* event, int64_t priority, DoneFn done) {
    on_done_ = std::move(done);
    return thread_.start(event, priority);
}

void BusWorker::stop() {
    thread_.stop();
    std::lock_guard lk(thread_.mutex());
    queue_.clear();
    done_.clear();
    outstanding_ = 0;
    views_ = published_;
}

void BusWorker::submit(const BusJob& in, bool replace) {
    BusJob job = in;
    job.epoch = epoch_.load();
    if (!running()) {
        // Before the thread starts or after it stopped: on the caller's thread.
        const BusJobDone d = transfer(job);
        views_[job.index] = published_[job.index] = *drivers_[job.index];
        if (on_done_)
            on_done_(d);
        return;
    }
    ++outstanding_;
    {
        std::lock_guard lk(thread_.mutex());
        outstanding_ -= queue_.push(job, replace);
    }
    if (holding_wakeups_)
        wakeup_owed_ = true;
    else
        thread_.notify();
}

void BusWorker::release_wakeups() {
    holding_wakeups_ = false;
    if (wakeup_owed_)
        thread_.notify();
    wakeup_owed_ = false;
}

void BusWorker::submit_first(std::span<const BusJob> jobs) {
    if (!running()) {
        for (const BusJob& j : jobs)
            submit(j);
        return;
    }
    {
        std::lock_guard lk(thread_.mutex());
        outstanding_ -= queue_.replace_all(jobs, epoch_.load());
    }
    outstanding_ += jobs.size();
    thread_.notify();
}

void BusWorker::drop_queued() {
    std::lock_guard lk(thread_.mutex());
    outstanding_ -= queue_.clear();
}

bool BusWorker::run_job(std::unique_lock<std::mutex>& lk) {
    const BusJob job = queue_.pop();
    busy_ = true;
    lk.unlock();
    const BusJobDone d = transfer(job); // nothing held
    lk.lock();
    published_[job.index] = *drivers_[job.index];
    done_.push_back(d);
    busy_ = false;
    owed_ = owed_ || d.error != IoError::None;
    finished_.notify_all();
    // One wake-up of the loop per batch (the queue ran dry), or every kWakeEvery jobs so the
    // books stay fresh when the bus never rests: a wake-up per transfer would cost the loop
    // more than the transfer when the device answers at once.
    return (queue_.empty() && (wake_at_once_ || owed_)) || done_.size() >= kWakeEvery;
}

void BusWorker::set_wake_at_once(bool at_once) {
    std::lock_guard lk(thread_.mutex());
    wake_at_once_ = at_once;
    if (at_once && !done_.empty() && queue_.empty() && !busy_)
        thread_.wake_loop(); // the batch was over before: its results now
}

void BusWorker::wake_when_done() {
    std::lock_guard lk(thread_.mutex());
    owed_ = true;
    if (!done_.empty() && queue_.empty() && !busy_)
        thread_.wake_loop();
}

BusJobDone BusWorker::transfer(const BusJob& job) {
    // A non-zero order from before the last kill is dropped here, at the last moment.
    if (job.kind == BusJobKind::Order && job.value != 0 && job.epoch != epoch_.load())
        return {job, IoError::None, true};
    BusGate* gate = gate_.load();
    // The thread's id, taken once: gettid() is a system call, and this runs for every transfer.
    thread_local const pid_t self = ::gettid();
    if (gate && !gate->enter(self))
        return {job, IoError::None, true}; // the crash handler has the bus; the process is ending
    ThrusterDriver& d = *drivers_[job.index];
    const IoError e = job.kind == BusJobKind::Probe   ? prober_->probe(static_cast<uint32_t>(job.value))
                      : job.kind == BusJobKind::Order ? d.send_order(job.value) : d.read_status();
    if (gate)
        gate->leave();
    return {job, e, false};
}

void BusWorker::deliver() {
    delivering_.clear();
    {
        std::lock_guard lk(thread_.mutex());
        delivering_.swap(done_);
        owed_ = owed_ && (busy_ || !queue_.empty()); // still owed for the rest of the batch
        for (const BusJobDone& d : delivering_)
            views_[d.job.index] = published_[d.job.index];
    }
    for (const BusJobDone& d : delivering_) {
        --outstanding_;
        if (on_done_)
            on_done_(d);
    }
}

void BusWorker::wait_idle() {
    while (running() && outstanding_ > 0) {
        {
            std::unique_lock lk(thread_.mutex());
            finished_.wait(lk, [this] { return !done_.empty() || (queue_.empty() && !busy_); });
        }
        const std::size_t before = outstanding_;
        deliver();
        if (outstanding_ == before && before > 0) {
            // Nothing was finished and nothing is queued: the count is off; do not hang.
            std::lock_guard lk(thread_.mutex());
            if (queue_.empty() && !busy_ && done_.empty())
                outstanding_ = 0;
        }
    }
}

} // namespace caracara
