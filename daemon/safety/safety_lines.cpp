#include "daemon/safety/safety_lines.hpp"

#include "daemon/loop/log.hpp"
#include "drivers/platform/io_error.hpp"
#include "drivers/platform/line_spec.hpp"

namespace caracara {

namespace {
constexpr uint64_t kReopenUs = 1'000'000;
// Not every tick: in sim mode each read is a round trip to the simulator. A kill output gone
// between two checks is found at the next, or at once by the kill's own write.
constexpr uint64_t kOutputCheckUs = 100'000;
} // namespace

std::string SafetyLines::open(bool kill_asserted, Listener* listener) {
    listener_ = listener;
    kill_asserted_ = kill_asserted;
    std::string err;
    if (settings_.kill_output) {
        kill_out_ = gpio_.request(line_spec(*settings_.kill_output), GpioMode::Output, kill_asserted ? 1 : 0, err);
        if (!kill_out_)
            return "gpio.kill_output: " + err;
        kill_output_changed();
    }
    if (settings_.power_off_output) {
        power_off_ = gpio_.request(line_spec(*settings_.power_off_output), GpioMode::Output, 0, err);
        if (!power_off_)
            return "gpio.power_off_output: " + err;
    }
    if (settings_.kill_switch) {
        if (std::string e = kill_switch_.open(); !e.empty())
            return e;
        poll();
    }
    return {};
}

void SafetyLines::close() {
    if (kill_output_watcher_)
        kill_output_watcher_->set_kill_output(nullptr);
    kill_switch_.close();
    reopen_timer_.reset();
}

void SafetyLines::poll() {
    check_outputs();
    if (!kill_switch_.is_open() || !listener_)
        return;
    if (const std::optional<bool> set = kill_switch_.read())
        listener_->kill_switch_read(*set);
}

void SafetyLines::check_outputs() {
    uint64_t now_us = 0;
    sd_event_now(event_, CLOCK_MONOTONIC, &now_us);
    if (now_us < next_output_check_us_)
        return;
    next_output_check_us_ = now_us + kOutputCheckUs;
    if (kill_out_)
        if (int r = kill_out_->get(); r < 0)
            output_lost(kill_out_, "kill output", r);
    if (power_off_)
        if (int r = power_off_->get(); r < 0)
            output_lost(power_off_, "power-off output", r);
}

void SafetyLines::switch_lost() {
    if (listener_)
        listener_->kill_switch_read(true);
    failsafes_.push(FailsafeCondition::KillSwitchUnreadable, true, "the kill switch cannot be read");
    schedule_reopen();
}

void SafetyLines::schedule_reopen() {
    sd_event_source* s = nullptr;
    uint64_t now_us = 0;
    sd_event_now(event_, CLOCK_MONOTONIC, &now_us);
    if (!reopen_timer_) {
        if (sd_event_add_time(event_, &s, CLOCK_MONOTONIC, now_us + kReopenUs, 1000, on_reopen, this) < 0)
            return;
        reopen_timer_.reset(s);
    } else {
        sd_event_source_set_time(reopen_timer_.get(), now_us + kReopenUs);
    }
    sd_event_source_set_enabled(reopen_timer_.get(), SD_EVENT_ONESHOT);
}

int SafetyLines::on_reopen(sd_event_source*, uint64_t, void* userdata) {
    auto* self = static_cast<SafetyLines*>(userdata);
    const GpioSettings& g = self->settings_;
    bool missing = false;
    // Quietly while gone: one log line when a line went, one when it is back.
    auto reopen_output = [&](std::unique_ptr<GpioLine>& line, const std::optional<GpioLineSettings>& cfg, int value,
                             const char* what) {
        if (line || !cfg)
            return;
        std::string err;
        line = self->gpio_.request(line_spec(*cfg), GpioMode::Output, value, err);
        if (line) {
            log_notice("%s %s is back", what, line_spec(*cfg).describe().c_str());
            self->kill_output_changed();
        }
        else
            missing = true;
    };
    reopen_output(self->kill_out_, g.kill_output, self->kill_asserted_ ? 1 : 0, "kill output");
    reopen_output(self->power_off_, g.power_off_output, 0, "power-off output");
    if (!self->output_missing())
        self->failsafes_.push(FailsafeCondition::SafetyLineLost, false, "every output line is back");
    if (self->kill_switch_.unreadable()) {
        if (std::string e = self->kill_switch_.open(); e.empty()) {
            log_notice("kill switch %s is back; its level decides", line_spec(*g.kill_switch).describe().c_str());
            self->poll(); // its level first: a switch still set keeps the kill
            self->failsafes_.push(FailsafeCondition::KillSwitchUnreadable, false, "the kill switch reads again");
        } else {
            missing = true;
        }
    }
    if (missing)
        self->schedule_reopen();
    return 0;
}

void SafetyLines::output_lost(std::unique_ptr<GpioLine>& line, const char* what, int err) {
    if (&line == &kill_out_ && kill_output_watcher_)
        kill_output_watcher_->set_kill_output(nullptr);
    line.reset();
    log_error("%s cannot be written (%s): vehicle killed; asking for it again once a second", what,
              errno_name(-err).c_str());
    schedule_reopen();
    failsafes_.push(FailsafeCondition::SafetyLineLost, true, std::string(what) + " went away");
}

void SafetyLines::set_kill_output(bool asserted) {
    kill_asserted_ = asserted;
    if (kill_out_)
        if (int r = kill_out_->set(asserted ? 1 : 0); r < 0)
            output_lost(kill_out_, "kill output", r);
}

void SafetyLines::assert_power_off() {
    if (power_off_)
        if (int r = power_off_->set(1); r < 0)
            output_lost(power_off_, "power-off output", r);
}

} // namespace caracara
