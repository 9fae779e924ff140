#include "drivers/platform/linux/libgpiod2_line.hpp"

#include <cerrno>
#include <chrono>
#include <new>
#include <stdexcept>
#include <system_error>

namespace caracara {

Libgpiod2Line::Libgpiod2Line(gpiod::line_request request, gpiod::line::offset offset, bool edges)
    : request_(std::move(request)), offset_(offset), edges_(edges), events_(edges ? 16 : 1) {}

Libgpiod2Line::~Libgpiod2Line() {
    try {
        request_.release();
    } catch (const std::exception&) {
        // the request's destructor closes its file descriptor anyway
    }
}

int Libgpiod2Line::errno_of(const std::exception& e) {
    if (auto* se = dynamic_cast<const std::system_error*>(&e))
        return se->code().value();
    if (dynamic_cast<const std::invalid_argument*>(&e))
        return EINVAL;
    if (dynamic_cast<const std::length_error*>(&e))
        return E2BIG;
    if (dynamic_cast<const std::domain_error*>(&e))
        return EDOM;
    if (dynamic_cast<const std::bad_alloc*>(&e))
        return ENOMEM;
    if (dynamic_cast<const gpiod::request_released*>(&e) || dynamic_cast<const gpiod::chip_closed*>(&e))
        return EBADF;
    return EIO;
}

int Libgpiod2Line::get() {
    try {
        return request_.get_value(offset_) == gpiod::line::value::ACTIVE ? 1 : 0;
    } catch (const std::exception& e) {
        return -errno_of(e);
    }
}

// An input: the kernel refuses a value for it with EPERM; nothing in the daemon asks.
int Libgpiod2Line::set(int) { return -EPERM; }

int Libgpiod2Line::event_fd() const {
    if (!edges_)
        return -1;
    try {
        return request_.fd();
    } catch (const std::exception&) {
        return -1;
    }
}

int Libgpiod2Line::drain_events() {
    if (!edges_)
        return 0;
    try {
        int n = 0;
        while (request_.wait_edge_events(std::chrono::nanoseconds(0)))
            n += static_cast<int>(request_.read_edge_events(events_));
        return n;
    } catch (const std::exception& e) {
        return -errno_of(e);
    }
}

} // namespace caracara
