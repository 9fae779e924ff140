// How a worker thread wakes the event loop: an eventfd watched by an I/O source the waker owns.
// The worker calls wake() (one write; wake-ups before the loop gets to it merge), the loop's
// handler runs at the given priority with the count drained.
#pragma once

#include "drivers/platform/event_loop.hpp"

#include <cstdint>
#include <functional>
#include <string>

namespace caracara {

class LoopWaker {
public:
    LoopWaker() = default;
    ~LoopWaker() { close(); }
    LoopWaker(const LoopWaker&) = delete;
    LoopWaker& operator=(const LoopWaker&) = delete;

    // "" or why the eventfd or its source could not be made. `woken` runs on the loop thread.
    std::string open(sd_event* event, int64_t priority, std::function<void()> woken);
    void close();
    // From any thread.
    void wake() const;

private:
    static int on_io(sd_event_source*, int fd, uint32_t, void* userdata);

    int fd_ = -1;
    SourcePtr source_;
    std::function<void()> woken_;
};

} // namespace caracara
