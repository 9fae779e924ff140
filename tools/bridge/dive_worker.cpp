#include "tools/bridge/dive_worker.hpp"

#include <boost/asio/post.hpp>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <sys/resource.h>

namespace caracara::bridge {

namespace {

// The lowest priority of SCHED_OTHER: the worker gets the CPU that the I/O thread, caracarad
// and the bus leave. Not SCHED_IDLE: a thread that may not run at all for as long as the CPU
// is busy can hold the process's memory map lock (a page fault while reading a dive) while the
// I/O thread waits for it.
constexpr int kNice = 19;

} // namespace

DiveWorker::DiveWorker(boost::asio::io_context& io, std::string directory) : io_(io), routes_(std::move(directory)) {
    // Who 0 with PRIO_PROCESS is the calling thread alone, on Linux. Lowering needs no
    // privilege (the unit allows this one call of @resources).
    boost::asio::post(pool_, [] {
        if (::setpriority(PRIO_PROCESS, 0, kNice) != 0)
            std::fprintf(stderr, "caracara-bridge: the dive worker stays at normal priority: %s\n", std::strerror(errno));
    });
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
