// The thread that answers /dives/ (DiveRoutes: listing every dive, reading one, converting it to
// MCAP), so the I/O thread that carries a Kill never waits behind the disk or the conversion
// (a full dive directory takes seconds to list). The answer comes back on the I/O thread. At
// most kMaxAnswers requests are in progress at once, from submit() until their answer is
// written (the client holds a ticket till then), so their memory is bounded too (DiveRoutes
// bounds each answer); past that, submit() says no and the client gets a 503.
// The thread runs at nice 19, so it also yields the CPU to the I/O thread, caracarad and the
// bus on a busy vehicle.
#pragma once

#include "tools/bridge/client_slots.hpp"
#include "tools/bridge/dive_routes.hpp"

#include <boost/asio/io_context.hpp>
#include <boost/asio/thread_pool.hpp>
#include <functional>
#include <memory>

namespace caracara::bridge {

class DiveWorker {
public:
    static constexpr std::size_t kMaxAnswers = 4;
    // The answer and its ticket: the request counts as in progress until the ticket goes.
    using Done = std::function<void(StaticFiles::Response, std::shared_ptr<void> ticket)>;

    // io: where `done` runs. directory: the recorder's directory.
    DiveWorker(boost::asio::io_context& io, std::string directory);
    ~DiveWorker();
    DiveWorker(const DiveWorker&) = delete;
    DiveWorker& operator=(const DiveWorker&) = delete;

    // Answers `request` on the worker, then calls done(response, ticket) on io; false (and
    // nothing called) when kMaxAnswers are in progress already.
    bool submit(std::shared_ptr<const StaticFiles::Request> request, Done done);

private:
    boost::asio::io_context& io_;
    const DiveRoutes routes_;
    boost::asio::thread_pool pool_{1};
    ClientSlots answers_{kMaxAnswers}; // touched on io's thread only
};

} // namespace caracara::bridge
