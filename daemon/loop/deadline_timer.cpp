#include "daemon/loop/deadline_timer.hpp"

#include "drivers/platform/io_error.hpp"

namespace caracara {

std::string DeadlineTimer::start(sd_event* event) {
    sd_event_source* s = nullptr;
    // Accuracy 1 us, like the loop's tick: the timeout is measured against its configured value.
    if (int r = sd_event_add_time(event, &s, CLOCK_MONOTONIC, 0, 1, on_time, this); r < 0)
        return "sd_event_add_time: " + errno_name(-r);
    source_.reset(s);
    sd_event_source_set_enabled(s, SD_EVENT_OFF);
    return {};
}

void DeadlineTimer::arm(uint64_t at_ns) {
    if (!source_ || at_ns == at_)
        return;
    at_ = at_ns;
    if (at_ns == kNever) {
        sd_event_source_set_enabled(source_.get(), SD_EVENT_OFF);
        return;
    }
    sd_event_source_set_time(source_.get(), at_ns / 1000);
    sd_event_source_set_enabled(source_.get(), SD_EVENT_ONESHOT);
}

int DeadlineTimer::on_time(sd_event_source*, uint64_t, void* userdata) {
    auto* self = static_cast<DeadlineTimer*>(userdata);
    self->at_ = kNever; // a one-shot source is off once it fired
    self->fired_();
    return 0;
}

} // namespace caracara
