#include "daemon/safety/kill_switch.hpp"

#include "daemon/loop/log.hpp"
#include "drivers/platform/io_error.hpp"
#include "drivers/platform/line_spec.hpp"

#include <sys/epoll.h>

namespace caracara {

std::string KillSwitch::open() {
    std::string err;
    line_ = gpio_.request(line_spec(*settings_), GpioMode::InputEdges, 0, err);
    if (!line_)
        return "gpio.kill_switch: " + err;
    // Above D-Bus and the bus work: the switch is the operator's hand on the vehicle.
    if (int fd = line_->event_fd(); fd >= 0) {
        sd_event_source* s = nullptr;
        if (int r = sd_event_add_io(event_, &s, fd, EPOLLIN, on_edge, this); r < 0) {
            line_.reset();
            return "gpio.kill_switch: cannot watch edges: " + errno_name(-r);
        }
        source_.reset(s);
        sd_event_source_set_priority(s, SD_EVENT_PRIORITY_IMPORTANT);
    }
    return {};
}

int KillSwitch::on_edge(sd_event_source*, int, uint32_t revents, void* userdata) {
    auto* self = static_cast<KillSwitch*>(userdata);
    if ((revents & (EPOLLHUP | EPOLLERR)) || self->line_->drain_events() < 0) {
        self->drop("the line went away");
        return 0;
    }
    self->edge_();
    return 0;
}

std::optional<bool> KillSwitch::read() {
    const int v = line_->get();
    if (v < 0) {
        drop(errno_name(-v));
        return std::nullopt;
    }
    return v == 1;
}

std::optional<bool> KillSwitch::level() const {
    const int v = line_ ? line_->get() : -1;
    return v < 0 ? std::nullopt : std::optional<bool>(v == 1);
}

void KillSwitch::drop(const std::string& why) {
    source_.reset();
    line_.reset();
    log_error("kill switch %s cannot be read (%s): treated as set; asking for it again once a second",
              line_spec(*settings_).describe().c_str(), why.c_str());
    lost_(why);
}

} // namespace caracara
