// The thread that answers /dives/ (DiveRoutes: listing every dive, reading one, converting it to
// MCAP), so the I/O thread that carries a Kill never waits behind the disk or the conversion
// (a full dive directory takes seconds to list). The answer comes back on the I/O thread. At
// most kMaxWaiting requests wait at once; past that, submit() says no and the client gets a 503.
// The thread runs at a lower priority (nice +10), so it also yields the CPU to the I/O thread
// and to caracarad on a busy vehicle.
#pragma once

#include "tools/bridge/dive_routes.hpp"

#include <boost/asio/io_context.hpp>
#include <boost/asio/thread_pool.hpp>
#include <functional>
#include <memory>

namespace caracara::bridge {

class DiveWorker {
public:
    static constexpr std::size_t kMaxWaiting = 8;
    using Done = std::function<void(StaticFiles::Response)>;

    // io: where `done` runs. directory: the recorder's directory.
    DiveWorker(boost::asio::io_context& io, std::string directory);
    ~DiveWorker();
    DiveWorker(const DiveWorker&) = delete;
    DiveWorker& operator=(const DiveWorker&) = delete;

    // Answers `request` on the worker, then calls done(response) on io; false (and nothing
    // called) when kMaxWaiting requests wait already.
    bool submit(std::shared_ptr<const StaticFiles::Request> request, Done done);

private:
    boost::asio::io_context& io_;
    const DiveRoutes routes_;
    boost::asio::thread_pool pool_{1};
    std::size_t waiting_ = 0; // touched on io's thread only
};

} // namespace caracara::bridge
