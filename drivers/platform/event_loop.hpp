// RAII for sd-event handles: the event loop is the one place the daemon and the simulator
// wait, so every layer that owns an event source (daemon/, dbus/, sim/) uses these.
#pragma once

#include <initializer_list>
#include <memory>
#include <systemd/sd-event.h>

namespace caracara {

struct EventUnref { void operator()(sd_event* e) const { sd_event_unref(e); } };
struct SourceUnref { void operator()(sd_event_source* s) const { sd_event_source_disable_unref(s); } };

using EventPtr = std::unique_ptr<sd_event, EventUnref>;
using SourcePtr = std::unique_ptr<sd_event_source, SourceUnref>;

// A program's event loop (the thread's default one) that ends on each of `exit_signals`: they
// are blocked first, as sd_event_add_signal needs. `on_signal` runs instead of a plain exit of
// the loop with status 0 when given (it must end the loop itself). Returns -errno.
int open_event_loop(EventPtr& out, std::initializer_list<int> exit_signals,
                    sd_event_signal_handler_t on_signal = nullptr);

} // namespace caracara
