#include "tools/bridge/bus_watch.hpp"

#include <boost/asio/error.hpp>
#include <chrono>
#include <ctime>
#include <poll.h>

namespace caracara::bridge {

BusWatch::BusWatch(boost::asio::io_context& io, sd_bus* bus, std::function<void()> on_lost)
    : bus_(bus), on_lost_(std::move(on_lost)), fd_(io, sd_bus_get_fd(bus)), timer_(io) {
    kick();
}

BusWatch::~BusWatch() {
    // The descriptor is sd-bus's: asio must not close it.
    boost::system::error_code ignored;
    fd_.cancel(ignored);
    (void)fd_.release();
}

void BusWatch::kick() {
    process();
    arm();
}

void BusWatch::process() {
    if (lost_)
        return;
    int r;
    do {
        r = sd_bus_process(bus_, nullptr);
    } while (r > 0);
    if (r < 0 && !lost_) {
        lost_ = true;
        if (on_lost_)
            on_lost_();
    }
}

void BusWatch::arm() {
    if (lost_)
        return;
    const int events = sd_bus_get_events(bus_);
    if (events < 0)
        return;
    if ((events & POLLIN) && !reading_) {
        reading_ = true;
        fd_.async_wait(boost::asio::posix::stream_descriptor::wait_read, [this](boost::system::error_code ec) {
            if (ec == boost::asio::error::operation_aborted)
                return; // the watch is being destroyed: `this` may be gone
            reading_ = false;
            kick();
        });
    }
    if ((events & POLLOUT) && !writing_) {
        writing_ = true;
        fd_.async_wait(boost::asio::posix::stream_descriptor::wait_write, [this](boost::system::error_code ec) {
            if (ec == boost::asio::error::operation_aborted)
                return;
            writing_ = false;
            kick();
        });
    }
    uint64_t until = 0;
    if (sd_bus_get_timeout(bus_, &until) >= 0 && until != UINT64_MAX) {
        // sd-bus's timeouts are CLOCK_MONOTONIC microseconds, as steady_clock is on Linux.
        timespec now{};
        clock_gettime(CLOCK_MONOTONIC, &now);
        const uint64_t now_us = static_cast<uint64_t>(now.tv_sec) * 1'000'000u + static_cast<uint64_t>(now.tv_nsec) / 1000u;
        const uint64_t wait = until > now_us ? until - now_us : 0;
        timer_.expires_after(std::chrono::microseconds(wait));
        timer_.async_wait([this](boost::system::error_code ec) {
            if (!ec)
                kick();
        });
    }
}

} // namespace caracara::bridge
