#include "drivers/platform/event_loop.hpp"

#include <cerrno>
#include <csignal>

namespace caracara {

int open_event_loop(EventPtr& out, std::initializer_list<int> exit_signals, sd_event_signal_handler_t on_signal) {
    sd_event* raw = nullptr;
    if (const int r = sd_event_default(&raw); r < 0)
        return r;
    EventPtr event(raw);
    sigset_t set;
    sigemptyset(&set);
    for (const int sig : exit_signals)
        sigaddset(&set, sig);
    if (sigprocmask(SIG_BLOCK, &set, nullptr) < 0)
        return -errno;
    // A null handler: sd-event exits the loop with the userdata as its code (0).
    for (const int sig : exit_signals)
        if (const int r = sd_event_add_signal(event.get(), nullptr, sig, on_signal, nullptr); r < 0)
            return r;
    out = std::move(event);
    return 0;
}

} // namespace caracara
