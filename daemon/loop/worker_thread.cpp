#include "daemon/loop/worker_thread.hpp"

namespace caracara {

std::string WorkerThread::start(sd_event* event, int64_t priority) {
    if (running())
        return {};
    if (std::string e = waker_.open(event, priority, [this] { jobs_.deliver(); }); !e.empty())
        return e;
    stopping_ = false;
    // Signals stay blocked in this thread as in the one that made it (main blocks them before
    // the daemon starts): the loop's signal sources must see them.
    thread_ = std::thread([this] { run(); });
    return {};
}

void WorkerThread::stop() {
    if (running()) {
        {
            std::lock_guard lk(mu_);
            stopping_ = true;
        }
        wake_.notify_all();
        thread_.join();
    }
    waker_.close();
}

void WorkerThread::run() {
    std::unique_lock lk(mu_);
    for (;;) {
        wake_.wait(lk, [this] { return stopping_ || jobs_.has_job(); });
        if (stopping_)
            return;
        if (jobs_.run_job(lk))
            waker_.wake();
    }
}

} // namespace caracara
