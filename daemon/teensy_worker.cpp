#include "daemon/teensy_worker.hpp"

#include "drivers/platform/io_error.hpp"

#include <cerrno>
#include <sys/eventfd.h>
#include <unistd.h>

namespace caracara {

std::string TeensyWorker::start(sd_event* event, int64_t priority) {
    if (running())
        return {};
    efd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    if (efd_ < 0)
        return "eventfd: " + errno_name(errno);
    sd_event_source* s = nullptr;
    if (int r = sd_event_add_io(event, &s, efd_, EPOLLIN, on_done, this); r < 0) {
        ::close(efd_);
        efd_ = -1;
        return "sd_event_add_io: " + errno_name(-r);
    }
    source_.reset(s);
    sd_event_source_set_priority(s, priority);
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
    source_.reset();
    if (efd_ >= 0) {
        ::close(efd_);
        efd_ = -1;
    }
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
            const uint64_t one = 1;
            [[maybe_unused]] const ssize_t n = ::write(efd_, &one, sizeof one);
        }
    }
}

int TeensyWorker::on_done(sd_event_source*, int fd, uint32_t, void* userdata) {
    uint64_t count = 0;
    [[maybe_unused]] const ssize_t n = ::read(fd, &count, sizeof count);
    static_cast<TeensyWorker*>(userdata)->deliver();
    return 0;
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
