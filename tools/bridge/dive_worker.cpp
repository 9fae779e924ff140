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
    std::shared_ptr<void> ticket = answers_.claim();
    if (!ticket)
        return false;
    // The ticket and `done` (which holds the session) are counted and destroyed on the I/O
    // thread only: they travel in the posted function's state, never copied on the worker.
    boost::asio::post(pool_, [this, request = std::move(request), done = std::move(done),
                              ticket = std::move(ticket)]() mutable {
        auto response = std::make_shared<StaticFiles::Response>(routes_.respond(*request));
        boost::asio::post(io_, [response, done = std::move(done), ticket = std::move(ticket)] {
            done(std::move(*response), ticket);
        });
    });
    return true;
}

} // namespace caracara::bridge
