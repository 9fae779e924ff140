#include "daemon/safety_lines.hpp"

#include "platform/line_spec.hpp"
#include "daemon/log.hpp"
#include "platform/io_error.hpp"

#include <sys/epoll.h>

namespace caracara {

std::string SafetyLines::open(bool kill_asserted, Listener* listener) {
    listener_ = listener;
    std::string err;
    if (settings_.kill_output) {
        kill_out_ = gpio_.request(line_spec(*settings_.kill_output), GpioMode::Output, kill_asserted ? 1 : 0, err);
        if (!kill_out_)
            return "gpio.kill_output: " + err;
    }
    if (settings_.power_off_output) {
        power_off_ = gpio_.request(line_spec(*settings_.power_off_output), GpioMode::Output, 0, err);
        if (!power_off_)
            return "gpio.power_off_output: " + err;
    }
    if (settings_.kill_switch) {
        kill_switch_ = gpio_.request(line_spec(*settings_.kill_switch), GpioMode::InputEdges, 0, err);
        if (!kill_switch_)
            return "gpio.kill_switch: " + err;
        // Above D-Bus and the bus work: the switch is the operator's hand on the vehicle.
        if (int fd = kill_switch_->event_fd(); fd >= 0) {
            sd_event_source* s = nullptr;
            if (int r = sd_event_add_io(event_, &s, fd, EPOLLIN, on_kill_switch, this); r < 0)
                return "gpio.kill_switch: cannot watch edges: " + errno_name(-r);
            kill_switch_source_.reset(s);
            sd_event_source_set_priority(s, SD_EVENT_PRIORITY_IMPORTANT);
        }
        poll();
    }
    return {};
}

void SafetyLines::close() { kill_switch_source_.reset(); }

int SafetyLines::on_kill_switch(sd_event_source*, int, uint32_t, void* userdata) {
    auto* self = static_cast<SafetyLines*>(userdata);
    if (self->kill_switch_->drain_events() < 0)
        log_error("kill switch events: the line went away");
    self->poll();
    return 0;
}

void SafetyLines::poll() {
    if (!kill_switch_ || !listener_)
        return;
    const int v = kill_switch_->get();
    if (v < 0)
        return;
    listener_->kill_switch_read(v == 1);
}

void SafetyLines::set_kill_output(bool asserted) {
    if (kill_out_)
        kill_out_->set(asserted ? 1 : 0);
}

void SafetyLines::assert_power_off() {
    if (power_off_)
        power_off_->set(1);
}

} // namespace caracara
