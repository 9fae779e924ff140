// Drives one sd-bus connection from a Boost.Asio io_context: reads when its fd is readable,
// writes when sd-bus has output queued, and wakes for its timeouts (pending method calls).
// Does not own the connection; the owner declares the watch after the bus so it ends first.
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/steady_timer.hpp>
#include <functional>
#include <systemd/sd-bus.h>

namespace caracara::bridge {

class BusWatch {
public:
    // on_lost: the connection closed (the daemon's bus went away); called once.
    BusWatch(boost::asio::io_context& io, sd_bus* bus, std::function<void()> on_lost);
    ~BusWatch();
    BusWatch(const BusWatch&) = delete;
    BusWatch& operator=(const BusWatch&) = delete;

    // Processes what is pending and re-arms the waits; call after queueing a message.
    void kick();

private:
    void process();
    void arm();

    sd_bus* bus_;
    std::function<void()> on_lost_;
    boost::asio::posix::stream_descriptor fd_;
    boost::asio::steady_timer timer_;
    bool reading_ = false, writing_ = false, lost_ = false;
};

} // namespace caracara::bridge
