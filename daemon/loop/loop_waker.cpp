#include "daemon/loop/loop_waker.hpp"

#include "drivers/platform/io_error.hpp"

#include <cerrno>
#include <sys/eventfd.h>
#include <unistd.h>

namespace caracara {

std::string LoopWaker::open(sd_event* event, int64_t priority, std::function<void()> woken) {
    close();
    fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    if (fd_ < 0)
        return "eventfd: " + errno_name(errno);
    sd_event_source* s = nullptr;
    if (int r = sd_event_add_io(event, &s, fd_, EPOLLIN, on_io, this); r < 0) {
        close();
        return "sd_event_add_io: " + errno_name(-r);
    }
    source_.reset(s);
    sd_event_source_set_priority(s, priority);
    woken_ = std::move(woken);
    return {};
}

void LoopWaker::close() {
    source_.reset();
    if (fd_ >= 0) {
        ::close(fd_);
        fd_ = -1;
    }
}

void LoopWaker::wake() const {
    const uint64_t one = 1;
    // A full counter (never, at 2^64 - 1) would only merge wake-ups.
    [[maybe_unused]] const ssize_t n = ::write(fd_, &one, sizeof one);
}

int LoopWaker::on_io(sd_event_source*, int fd, uint32_t, void* userdata) {
    uint64_t count = 0;
    [[maybe_unused]] const ssize_t n = ::read(fd, &count, sizeof count);
    auto* self = static_cast<LoopWaker*>(userdata);
    if (self->woken_)
        self->woken_();
    return 0;
}

} // namespace caracara
