// The thread of a worker that keeps the event loop off a slow device (BusWorker: the I2C
// transfers; TeensyWorker: the SPI frames): starting and joining it, its lock, waking it for a
// job and waking the loop (LoopWaker) for the results. The worker keeps its own queue and
// results under mutex() and says, through Jobs, whether there is a job and how one runs.
#pragma once

#include "daemon/loop/loop_waker.hpp"
#include "drivers/platform/event_loop.hpp"

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

namespace caracara {

class WorkerThread {
public:
    class Jobs {
    public:
        // Under the lock: a job is queued.
        virtual bool has_job() const = 0;
        // Called with `lk` held: takes the next job, runs it with `lk` released (nothing held
        // while a device is on the wire), holds it again to file the result. Returns whether the
        // loop is to be woken for the results (one wake-up per batch, not per job).
        virtual bool run_job(std::unique_lock<std::mutex>& lk) = 0;
        // On the loop thread, when woken: the finished jobs' results.
        virtual void deliver() = 0;

    protected:
        ~Jobs() = default;
    };

    explicit WorkerThread(Jobs& jobs) : jobs_(jobs) {}
    ~WorkerThread() { stop(); }
    WorkerThread(const WorkerThread&) = delete;
    WorkerThread& operator=(const WorkerThread&) = delete;

    // "" or why the loop's wake-up source could not be made; Jobs::deliver runs at `priority`.
    std::string start(sd_event* event, int64_t priority);
    // Joins the thread once the job on the wire is over, and closes the wake-up source.
    void stop();
    bool running() const { return thread_.joinable(); }

    std::mutex& mutex() const { return mu_; }
    // A job was queued (call after releasing mutex()).
    void notify() { wake_.notify_one(); }
    // The loop is to run Jobs::deliver (from any thread).
    void wake_loop() const { waker_.wake(); }

private:
    void run();

    Jobs& jobs_;
    mutable std::mutex mu_;
    std::condition_variable wake_;
    bool stopping_ = false; // under mu_
    LoopWaker waker_;
    std::thread thread_;
};

} // namespace caracara
