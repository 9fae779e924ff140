#include "daemon/teensy/teensy_reopen.hpp"

#include <memory>

namespace caracara {

namespace {
constexpr uint64_t kReopenUs = 1'000'000;
} // namespace

void TeensyReopen::schedule() {
    uint64_t now_us = 0;
    sd_event_now(event_, CLOCK_MONOTONIC, &now_us);
    if (!timer_) {
        sd_event_source* s = nullptr;
        if (sd_event_add_time(event_, &s, CLOCK_MONOTONIC, now_us + kReopenUs, 1000, on_timer, this) < 0)
            return;
        timer_.reset(s);
    }
    sd_event_source_set_time(timer_.get(), now_us + kReopenUs);
    sd_event_source_set_enabled(timer_.get(), SD_EVENT_ONESHOT);
}

int TeensyReopen::on_timer(sd_event_source*, uint64_t, void* userdata) {
    auto* self = static_cast<TeensyReopen*>(userdata);
    if (self->is_open_())
        return 0;
    auto r = std::make_shared<int>(0);
    self->worker_.submit([self, r] { *r = self->spi_.is_open() ? 0 : self->spi_.open(); },
                         [self, r] {
                             if (self->is_open_())
                                 return;
                             if (*r < 0)
                                 self->schedule(); // quietly: one line when it went, one when it is back
                             else
                                 self->reopened_();
                         });
    return 0;
}

} // namespace caracara
