#include "tools/bridge/dive_worker.hpp"

#include <boost/asio/post.hpp>
#include <sys/resource.h>
#include <unistd.h>

namespace caracara::bridge {

namespace {

constexpr int kNice = 10;

} // namespace

DiveWorker::DiveWorker(boost::asio::io_context& io, std::string directory) : io_(io), routes_(std::move(directory)) {
    // On Linux a thread's id names the thread alone: only the worker is lowered.
    boost::asio::post(pool_, [] { (void)::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), kNice); });
}

DiveWorker::~DiveWorker() {
    // Requests not started are dropped (their clients are going too); one in progress finishes.
    pool_.stop();
    pool_.join();
}

bool DiveWorker::submit(std::shared_ptr<const StaticFiles::Request> request, Done done) {
    if (waiting_ >= kMaxWaiting)
        return false;
    ++waiting_;
    boost::asio::post(pool_, [this, request = std::move(request), done = std::move(done)]() mutable {
        auto response = std::make_shared<StaticFiles::Response>(routes_.respond(*request));
        // `done` (which holds the session) moves to the I/O thread: it is never destroyed here.
        boost::asio::post(io_, [this, response, done = std::move(done)] {
            --waiting_;
            done(std::move(*response));
        });
    });
    return true;
}

} // namespace caracara::bridge
