#include "tools/caracaractl/hold.hpp"

#include "tools/caracaractl/render.hpp"

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <iostream>
#include <optional>
#include <unistd.h>

namespace caracara::ctl {

using namespace caracara::client; // the vehicle's D-Bus client (tools/client)

namespace {

constexpr uint64_t kMaxIntervalUsec = 100'000;
constexpr uint64_t kMinIntervalUsec = 1'000;
// A re-send unanswered for this long ends the hold (the daemon has long zeroed by then).
constexpr uint64_t kResendTimeoutUsec = 5'000'000;

struct Hold {
    Client& client;
    sd_event* event;
    const char* member;
    const Client::Appender& append;
    uint64_t interval_usec;
    caracara::dbus::SlotPtr pending; // the re-send awaiting its reply
    std::optional<Failure> failure;
    int signal = 0;
};

// Ends the loop with the first failure (no exception may cross sd-bus or sd-event).
void fail(Hold& h, Failure f) {
    if (!h.failure)
        h.failure = std::move(f);
    sd_event_exit(h.event, h.failure->code);
}

int on_reply(sd_bus_message* m, void* userdata, sd_bus_error*) {
    auto& h = *static_cast<Hold*>(userdata);
    h.pending.reset(); // sd-bus keeps the slot alive until this callback returns
    if (sd_bus_message_is_method_error(m, nullptr) > 0) {
        if (stop_signal_pending() && !sd_bus_is_open(h.client.bus())) {
            h.signal = SIGINT;
            sd_event_exit(h.event, kExitOk);
            return 0;
        }
        const sd_bus_error* error = sd_bus_message_get_error(m);
        fail(h, h.client.failure_for(*error, -sd_bus_message_get_errno(m), kResendTimeoutUsec));
    }
    return 0;
}

void resend(Hold& h) {
    try {
        caracara::dbus::MessagePtr request = h.client.new_call(kRootPath, kVehicleIface, h.member, h.append);
        sd_bus_slot* slot = nullptr;
        const int r = sd_bus_call_async(h.client.bus(), &slot, request.get(), on_reply, &h, kResendTimeoutUsec);
        if (r < 0)
            fail(h, h.client.failure_for(SD_BUS_ERROR_NULL, r, kResendTimeoutUsec));
        else
            h.pending.reset(slot);
    } catch (const Failure& f) {
        fail(h, f);
    }
}

int on_tick(sd_event_source* source, uint64_t usec, void* userdata) {
    auto& h = *static_cast<Hold*>(userdata);
    // One call in flight at a time: a daemon that is slow to answer gains nothing from a queue.
    if (!h.pending)
        resend(h);
    uint64_t now = 0;
    sd_event_now(h.event, CLOCK_MONOTONIC, &now);
    uint64_t next = usec + h.interval_usec;
    if (next <= now) // fell behind (stopped, suspended): keep the rhythm from now
        next = now + h.interval_usec;
    if (int r = sd_event_source_set_time(source, next); r < 0)
        fail(h, Failure{kExitUnavailable, std::string("cannot re-arm the re-send timer: ") + std::strerror(-r)});
    return 0;
}

int on_duration(sd_event_source*, uint64_t, void* userdata) {
    return sd_event_exit(static_cast<Hold*>(userdata)->event, kExitOk);
}

int on_signal(sd_event_source*, const signalfd_siginfo* info, void* userdata) {
    auto& h = *static_cast<Hold*>(userdata);
    h.signal = static_cast<int>(info->ssi_signo);
    return sd_event_exit(h.event, kExitOk);
}

// sd-bus synthesizes org.freedesktop.DBus.Local.Disconnected when the bus connection drops.
int on_message(sd_bus_message* m, void* userdata, sd_bus_error*) {
    auto& h = *static_cast<Hold*>(userdata);
    if (sd_bus_message_is_signal(m, "org.freedesktop.DBus.Local", "Disconnected") <= 0)
        return 0;
    if (stop_signal_pending()) { // Ctrl-C also ended ssh (-H): a release, not a lost link
        h.signal = SIGINT;
        return sd_event_exit(h.event, kExitOk);
    }
    fail(h, h.client.lost_connection("disconnected"));
    return 0;
}

void check(int r, const char* what) {
    if (r < 0)
        throw Failure{kExitUnavailable, std::string("cannot hold the command: ") + what + ": " + std::strerror(-r)};
}

uint32_t command_timeout_ms(Client& client) {
    try {
        const Value v = client.get_property(kRootPath, kVehicleIface, "CommandTimeoutMs");
        return static_cast<uint32_t>(std::min<uint64_t>(v.unsigned_integer(), UINT32_MAX));
    } catch (const Failure& f) {
        if (f.code != kExitRefused)
            throw;
        return 0; // a daemon without the property: the default interval
    }
}

} // namespace

uint64_t resend_interval_usec(uint32_t command_timeout_ms) {
    if (command_timeout_ms == 0)
        return kMaxIntervalUsec;
    const uint64_t third = uint64_t{command_timeout_ms} * 1000 / 3;
    return std::clamp(third, kMinIntervalUsec, kMaxIntervalUsec);
}

std::string format_seconds(uint64_t usec) {
    if (usec % 100'000 == 0)
        return strf("%llu.%llu s", static_cast<unsigned long long>(usec / 1'000'000),
                    static_cast<unsigned long long>(usec % 1'000'000 / 100'000));
    std::string text = strf("%llu.%06llu", static_cast<unsigned long long>(usec / 1'000'000),
                            static_cast<unsigned long long>(usec % 1'000'000));
    text.erase(text.find_last_not_of('0') + 1);
    return text + " s";
}

int hold_command(Client& client, const char* member, const Client::Appender& append,
                 const std::string& description, const HoldOptions& options) {
    if (options.once) {
        client.call(kRootPath, kVehicleIface, member, append);
        return kExitOk;
    }
    const uint64_t interval = resend_interval_usec(command_timeout_ms(client));
    client.call(kRootPath, kVehicleIface, member, append); // refused: exits at once, nothing held

    sd_event* raw_event = nullptr;
    check(sd_event_new(&raw_event), "cannot create the event loop");
    caracara::dbus::EventPtr event(raw_event);
    Hold h{client, raw_event, member, append, interval, {}, {}, 0};

    sigset_t mask;
    sigemptyset(&mask);
    sigaddset(&mask, SIGINT);
    sigaddset(&mask, SIGTERM);
    check(sigprocmask(SIG_BLOCK, &mask, nullptr) < 0 ? -errno : 0, "cannot block signals");
    sd_event_source* raw_source = nullptr;
    // Signals before the bus: with -H the same Ctrl-C ends ssh, and the release must win.
    check(sd_event_add_signal(raw_event, &raw_source, SIGINT, on_signal, &h), "cannot watch SIGINT");
    caracara::dbus::SourcePtr sigint(raw_source);
    check(sd_event_source_set_priority(raw_source, SD_EVENT_PRIORITY_IMPORTANT), "cannot order SIGINT");
    check(sd_event_add_signal(raw_event, &raw_source, SIGTERM, on_signal, &h), "cannot watch SIGTERM");
    caracara::dbus::SourcePtr sigterm(raw_source);
    check(sd_event_source_set_priority(raw_source, SD_EVENT_PRIORITY_IMPORTANT), "cannot order SIGTERM");

    constexpr uint64_t kAccuracyUsec = 1'000;
    check(sd_event_add_time_relative(raw_event, &raw_source, CLOCK_MONOTONIC, interval, kAccuracyUsec, on_tick, &h),
          "cannot create the re-send timer");
    caracara::dbus::SourcePtr tick(raw_source);
    check(sd_event_source_set_enabled(raw_source, SD_EVENT_ON), "cannot enable the re-send timer");
    caracara::dbus::SourcePtr duration;
    if (options.duration_usec) {
        check(sd_event_add_time_relative(raw_event, &raw_source, CLOCK_MONOTONIC, options.duration_usec,
                                         kAccuracyUsec, on_duration, &h),
              "cannot create the duration timer");
        duration.reset(raw_source);
    }

    sd_bus* bus = client.bus();
    sd_bus_slot* raw_slot = nullptr;
    check(sd_bus_add_filter(bus, &raw_slot, on_message, &h), "cannot watch the connection");
    caracara::dbus::SlotPtr filter(raw_slot);
    check(sd_bus_attach_event(bus, raw_event, SD_EVENT_PRIORITY_NORMAL), "cannot attach the bus");

    std::cout << "holding " << description
              << (options.duration_usec ? " for " + format_seconds(options.duration_usec) : std::string())
              << "; Ctrl-C to stop" << std::endl;
    const int r = sd_event_loop(raw_event);
    sd_bus_detach_event(bus);
    h.pending.reset();
    if (h.failure)
        throw *h.failure;
    check(r, "event loop failed");
    // No zero from here: the daemon zeroes when this client leaves (at exit), and a zero sent
    // now could override another client that has taken over meanwhile.
    if (h.signal == SIGINT && isatty(STDOUT_FILENO))
        std::cout << '\n'; // after the terminal's ^C
    std::cout << "released: caracarad zeroes the thrusters when this client leaves" << std::endl;
    return kExitOk;
}

} // namespace caracara::ctl
