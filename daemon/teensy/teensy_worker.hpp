// The worker that carries the Teensy's SPI frames on its own thread (WorkerThread), so that a
// slow or hung Teensy holds only itself: a kill, a D-Bus reply and the watchdog never wait for
// a frame (busy resends sleep too). Jobs run one at a time in the order handed over; each job's
// `done` runs afterwards on the loop thread, with one wake-up of the loop per batch (the queue
// ran dry). Only the thread touches the link and the SPI descriptor while a job is out; the
// loop reads the link's counters through the copy made after the last job.
#pragma once

#include "daemon/loop/worker_thread.hpp"
#include "drivers/devices/teensy_link.hpp"
#include "drivers/platform/event_loop.hpp"

#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

namespace caracara {

class TeensyWorker final : private WorkerThread::Jobs {
public:
    using Work = std::function<void()>; // on the worker's thread
    using Done = std::function<void()>; // then on the loop thread

    explicit TeensyWorker(const TeensyLink& link) : link_(link), counters_(link.counters()) {}
    ~TeensyWorker() { stop(); }
    TeensyWorker(const TeensyWorker&) = delete;
    TeensyWorker& operator=(const TeensyWorker&) = delete;

    std::string start(sd_event* event, int64_t priority) { return thread_.start(event, priority); }
    // Joins the thread once the job on the wire is over; the finished and queued jobs' `done`
    // run here (queued ones after their work, on this thread: the way out still stops the wheels).
    void stop();
    bool running() const { return thread_.running(); }

    // Before start and after stop the work runs at once, on the caller's thread. `wake`: the
    // loop is woken for its `done`; without it, `done` waits for the next wake-up or collect()
    // (the cycle's poll: its result is taken at the next cycle, at no wake-up of its own).
    void submit(Work work, Done done, bool wake = true);
    // Runs the `done` of the jobs finished so far (loop thread).
    void collect() { deliver(); }
    bool idle() const { return outstanding_ == 0; }
    // The link's counters as of the last finished job.
    const TeensyLinkCounters& counters() const { return counters_; }

private:
    struct Job {
        Work work;
        Done done;
        bool wake = true;
    };
    bool has_job() const override { return !queue_.empty(); }
    bool run_job(std::unique_lock<std::mutex>& lk) override;
    void deliver() override;
    void run_here(Job& job);

    const TeensyLink& link_;
    TeensyLinkCounters counters_;    // loop thread
    TeensyLinkCounters published_{}; // under the lock
    std::size_t outstanding_ = 0;    // loop thread

    std::deque<Job> queue_;        // under the lock
    std::vector<Done> done_;       // under the lock
    bool wake_owed_ = false;       // under the lock: a job in done_ wants the loop woken
    std::vector<Done> delivering_; // loop thread; reused
    WorkerThread thread_{*this};   // last: joined before the rest goes
};

} // namespace caracara
