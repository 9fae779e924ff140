#include "dbus/announcer.hpp"

#include <systemd/sd-bus.h>

namespace caracara::dbus {

void Announcer::request(uint32_t changes) {
    pending_ |= changes;
    sd_event* ev = sd_bus_get_event(bus_);
    if (!source_ && ev) {
        sd_event_source* s = nullptr;
        if (sd_event_add_defer(ev, &s, on_flush, this) >= 0) {
            source_.reset(s);
            sd_event_source_set_priority(s, kAnnouncePriority);
        }
    }
    if (source_)
        sd_event_source_set_enabled(source_.get(), SD_EVENT_ONESHOT);
    else
        on_flush(nullptr, this); // no event loop to defer to: now
}

void Announcer::hold(bool held) {
    held_ = held;
    if (!held && pending_)
        request(0);
}

int Announcer::on_flush(sd_event_source*, void* userdata) {
    auto* self = static_cast<Announcer*>(userdata);
    constexpr uint32_t kWaitForTheWire = kChangeMotors | kChangeController | kTelemetryTick;
    if (self->held_ && !(self->pending_ & ~kWaitForTheWire))
        return 0; // hold(false) brings them
    uint32_t changes = self->pending_;
    self->pending_ = 0;
    if ((changes & kTelemetryTick) && ++self->ticks_ % 5 == 0)
        changes |= kCounterTick;
    self->flush_(changes);
    return 0;
}

} // namespace caracara::dbus
