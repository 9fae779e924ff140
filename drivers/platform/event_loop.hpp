// RAII for sd-event handles: the event loop is the one place the daemon and the simulator
// wait, so every layer that owns an event source (daemon/, dbus/, sim/) uses these.
#pragma once

#include <memory>
#include <systemd/sd-event.h>

namespace caracara {

struct EventUnref { void operator()(sd_event* e) const { sd_event_unref(e); } };
struct SourceUnref { void operator()(sd_event_source* s) const { sd_event_source_disable_unref(s); } };

using EventPtr = std::unique_ptr<sd_event, EventUnref>;
using SourcePtr = std::unique_ptr<sd_event_source, SourceUnref>;

} // namespace caracara
