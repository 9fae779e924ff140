#include "daemon/recovery/bus_loss.hpp"

#include "core/clock.hpp"

#include <utility>

namespace caracara {

void BusLoss::watch() {
    // Commands behave as before during a short recovery; one that outlasts the command timeout
    // has left the thrusters unreachable for longer than any command may stand.
    const uint64_t at_us = (monotonic_ns() + ms_to_ns(control_.command_timeout_ms)) / 1000;
    if (!timer_) {
        sd_event_source* s = nullptr;
        if (sd_event_add_time(event_, &s, CLOCK_MONOTONIC, at_us, 1, on_timer, this) < 0)
            return;
        timer_.reset(s);
    }
    sd_event_source_set_time(timer_.get(), at_us);
    sd_event_source_set_enabled(timer_.get(), SD_EVENT_ONESHOT);
}

void BusLoss::recovered() {
    if (timer_)
        sd_event_source_set_enabled(timer_.get(), SD_EVENT_OFF);
    if (std::exchange(pushed_, false))
        failsafes_.push(FailsafeCondition::BusLost, false, "the I2C bus is back");
}

int BusLoss::on_timer(sd_event_source*, uint64_t, void* userdata) {
    auto* self = static_cast<BusLoss*>(userdata);
    if (self->bus_.monitor().recovering())
        self->declare("locked up for longer than the command timeout (" +
                      std::to_string(self->control_.command_timeout_ms) + " ms)");
    return 0;
}

void BusLoss::declare(const std::string& why) {
    BusTelemetry& tm = bus_.monitor().telemetry();
    if (tm.state == BusState::Lost)
        return;
    tm.state = BusState::Lost;
    tm.last_recovery_error = why;
    pushed_ = true;
    failsafes_.push(FailsafeCondition::BusLost, true, "I2C bus lost: " + why);
    events_.changed(kChangeState | kChangeBus);
}

} // namespace caracara
