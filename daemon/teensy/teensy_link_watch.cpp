#include "daemon/teensy/teensy_link_watch.hpp"

#include "core/clock.hpp"
#include "drivers/platform/io_error.hpp"

namespace caracara {

std::string TeensyLinkWatch::start(sd_event* event) {
    sd_event_source* s = nullptr;
    if (int r = sd_event_add_time(event, &s, CLOCK_MONOTONIC, 0, 1000, on_timer, this); r < 0)
        return "sd_event_add_time: " + errno_name(-r);
    timer_.reset(s);
    arm(monotonic_ns() + silence_ns_);
    return {};
}

bool TeensyLinkWatch::lose(TeensyLoss why) {
    if (loss_ != TeensyLoss::None)
        return false;
    loss_ = why;
    return true;
}

void TeensyLinkWatch::asked() {
    if (asked_ns_ == 0)
        asked_ns_ = monotonic_ns();
}

bool TeensyLinkWatch::heard(uint64_t now) {
    asked_ns_ = 0;
    answered_ = true;
    if (loss_ == TeensyLoss::None || !open_())
        return false;
    loss_ = TeensyLoss::None;
    arm(now + silence_ns_);
    return true;
}

void TeensyLinkWatch::arm(uint64_t at_ns) {
    if (!timer_)
        return;
    sd_event_source_set_time(timer_.get(), at_ns / 1000);
    sd_event_source_set_enabled(timer_.get(), SD_EVENT_ONESHOT);
}

int TeensyLinkWatch::on_timer(sd_event_source*, uint64_t, void* userdata) {
    auto* self = static_cast<TeensyLinkWatch*>(userdata);
    self->collect_(); // a valid frame already in counts
    const uint64_t now = monotonic_ns();
    if (self->loss_ != TeensyLoss::None)
        return 0; // armed again at its next valid frame
    // A Teensy not fitted that never answered, or a node not open, is not relied on.
    if (!self->open_() || !(self->fitted_ || self->answered_)) {
        self->arm(now + self->silence_ns_);
        return 0;
    }
    if (self->asked_ns_ == 0 || now - self->asked_ns_ < self->silence_ns_) {
        self->arm((self->asked_ns_ ? self->asked_ns_ : now) + self->silence_ns_);
        return 0;
    }
    self->on_silent_((now - self->asked_ns_) / 1'000'000);
    return 0;
}

} // namespace caracara
