#include "tools/caracaractl/monitor.hpp"

#include "tools/caracaractl/render.hpp"

#include <csignal>
#include <cstring>
#include <iostream>
#include <map>
#include <string>

namespace caracara::ctl {

using namespace caracara::client; // the vehicle's D-Bus client (tools/client)

namespace {

struct Monitor {
    Client& client;
    sd_event* event;
    bool all;
    // The last value shown of every property (rendered), keyed by path, interface and name: the
    // daemon re-announces values that did not change (MotorValues after each re-sent command).
    std::map<std::string, std::string> last;
};

std::string property_key(std::string_view path, std::string_view iface, std::string_view name) {
    return std::string(path) + ' ' + std::string(iface) + ' ' + std::string(name);
}

struct Counter {
    std::string_view iface;
    std::string_view property;
};

// Counters that move with every control-loop cycle, status read or Teensy frame, and the time of
// each orientation reading (Orientation's own line says what changed): printed, they would bury
// every other change. Error counters (Nacks, Timeouts, Errors, ...) are not here.
constexpr Counter kFastCounters[] = {
    {kVehicleIface, "Cycles"},       {kVehicleIface, "CommandAgeMs"}, {kThrusterIface, "OrdersSent"},
    {kThrusterIface, "StatusReads"}, {kTeensyIface, "Frames"},        {kTeensyIface, "BusyRetries"},
    {kBusIface, "Transactions"},     {kTeensyIface, "OrientationReadNs"},
};

void print_line(const std::string& text) { std::cout << timestamp_now() << ' ' << text << std::endl; }

// Runs a callback body; a Failure ends the loop with its exit code (no exception may cross sd-bus).
template <typename F>
int guarded(Monitor& mon, F body) {
    try {
        body();
    } catch (const Failure& f) {
        std::cerr << "caracaractl: " << f.message << '\n';
        sd_event_exit(mon.event, f.code);
    }
    return 0;
}

int on_properties_changed(sd_bus_message* m, void* userdata, sd_bus_error*) {
    auto& mon = *static_cast<Monitor*>(userdata);
    return guarded(mon, [&] {
        if (sd_bus_message_has_signature(m, "sa{sv}as") <= 0)
            return;
        const char* path = sd_bus_message_get_path(m);
        const std::string iface = read_value(m).s;
        const Value changed = read_value(m);
        const Value invalidated = read_value(m);
        auto shown = [&](const std::string& name) { return mon.all || !is_fast_counter(iface, name); };
        std::string line;
        for (const Value& entry : changed.items) {
            if (entry.items.size() != 2 || !shown(entry.items[0].s))
                continue;
            const std::string& name = entry.items[0].s;
            std::string text = render_property(name, entry.items[1]);
            std::string& last = mon.last[property_key(path ? path : "", iface, name)];
            if (!mon.all && text == last)
                continue;
            last = text;
            line += ' ' + name + '=' + text;
        }
        for (const Value& name : invalidated.items)
            if (shown(name.s))
                line += ' ' + name.s + "=(changed)";
        if (!line.empty())
            print_line(object_label(path ? path : "") + line);
    });
}

// The daemon's Failsafe signal: a failsafe raised, said in words.
int on_failsafe(sd_bus_message* m, void* userdata, sd_bus_error*) {
    auto& mon = *static_cast<Monitor*>(userdata);
    return guarded(mon, [&] {
        const char *condition = nullptr, *action = nullptr;
        int32_t thruster = -1;
        if (sd_bus_message_read(m, "ssi", &condition, &action, &thruster) < 0)
            return;
        print_line(std::string("FAILSAFE ") + condition + " -> " + action +
                   (thruster >= 0 ? " (thruster " + std::to_string(thruster) + ")" : std::string()));
    });
}

int on_name_owner_changed(sd_bus_message* m, void* userdata, sd_bus_error*) {
    auto& mon = *static_cast<Monitor*>(userdata);
    const char *name = nullptr, *old_owner = nullptr, *new_owner = nullptr;
    if (sd_bus_message_read(m, "sss", &name, &old_owner, &new_owner) < 0 || std::strcmp(name, kService) != 0)
        return 0;
    if (!new_owner || !*new_owner) {
        print_line(std::string("caracarad left ") + mon.client.choice().describe());
        sd_event_exit(mon.event, kExitRefused);
    }
    return 0;
}

// sd-bus synthesizes org.freedesktop.DBus.Local.Disconnected when the bus connection drops.
int on_message(sd_bus_message* m, void* userdata, sd_bus_error*) {
    auto& mon = *static_cast<Monitor*>(userdata);
    if (sd_bus_message_is_signal(m, "org.freedesktop.DBus.Local", "Disconnected") <= 0)
        return 0;
    if (stop_signal_pending()) // Ctrl-C also ended ssh (-H): the end the user asked for
        return sd_event_exit(mon.event, kExitOk);
    const Failure f = mon.client.lost_connection("disconnected");
    std::cerr << "caracaractl: " << f.message << '\n';
    return sd_event_exit(mon.event, f.code);
}

int on_signal(sd_event_source* source, const signalfd_siginfo*, void*) {
    return sd_event_exit(sd_event_source_get_event(source), kExitOk);
}

void check(int r, const char* what) {
    if (r < 0)
        throw Failure{kExitUnavailable, std::string("monitor: ") + what + ": " + std::strerror(-r)};
}

} // namespace

bool is_fast_counter(std::string_view iface, std::string_view property) {
    for (const Counter& c : kFastCounters)
        if (c.iface == iface && c.property == property)
            return true;
    return false;
}

int run_monitor(Client& client, bool all) {
    sd_bus* bus = client.bus();
    sd_event* raw_event = nullptr;
    check(sd_event_new(&raw_event), "cannot create the event loop");
    caracara::dbus::EventPtr event(raw_event);
    Monitor mon{client, raw_event, all, {}};

    sigset_t mask;
    sigemptyset(&mask);
    sigaddset(&mask, SIGINT);
    sigaddset(&mask, SIGTERM);
    check(sigprocmask(SIG_BLOCK, &mask, nullptr) < 0 ? -errno : 0, "cannot block signals");
    // Signals before the bus: with -H the same Ctrl-C ends ssh, and the plain exit must win.
    caracara::dbus::SourcePtr signals[2];
    for (int i = 0; const int sig : {SIGINT, SIGTERM}) {
        sd_event_source* raw_source = nullptr;
        check(sd_event_add_signal(raw_event, &raw_source, sig, on_signal, nullptr), "cannot watch a signal");
        signals[i++].reset(raw_source);
        check(sd_event_source_set_priority(raw_source, SD_EVENT_PRIORITY_IMPORTANT), "cannot order a signal");
    }

    // Subscribe first (sd_bus_add_match waits for the bus to confirm), then read the current
    // state, so that no change falls between the two.
    const std::string changes = std::string("type='signal',sender='") + kService +
                                "',interface='org.freedesktop.DBus.Properties',member='PropertiesChanged',"
                                "path_namespace='" + kRootPath + "'";
    const std::string owner = std::string("type='signal',sender='org.freedesktop.DBus',path='/org/freedesktop/DBus',"
                                          "interface='org.freedesktop.DBus',member='NameOwnerChanged',arg0='") +
                              kService + "'";
    sd_bus_slot* raw_slot = nullptr;
    check(sd_bus_add_match(bus, &raw_slot, changes.c_str(), on_properties_changed, &mon), "cannot subscribe");
    caracara::dbus::SlotPtr changes_slot(raw_slot);
    check(sd_bus_add_match(bus, &raw_slot, owner.c_str(), on_name_owner_changed, &mon), "cannot subscribe");
    caracara::dbus::SlotPtr owner_slot(raw_slot);
    const std::string failsafe = std::string("type='signal',sender='") + kService + "',path='" + kRootPath +
                                 "',interface='" + kVehicleIface + "',member='Failsafe'";
    check(sd_bus_add_match(bus, &raw_slot, failsafe.c_str(), on_failsafe, &mon), "cannot subscribe");
    caracara::dbus::SlotPtr failsafe_slot(raw_slot);
    check(sd_bus_add_filter(bus, &raw_slot, on_message, &mon), "cannot watch the connection");
    caracara::dbus::SlotPtr filter_slot(raw_slot);

    const Objects objects = client.get_objects();
    for (const auto& [path, ifaces] : objects)
        for (const auto& [iface, props] : ifaces)
            for (const auto& [name, value] : props)
                mon.last[property_key(path, iface, name)] = render_property(name, value);
    print_line(summary_line(objects));

    check(sd_bus_attach_event(bus, raw_event, SD_EVENT_PRIORITY_NORMAL), "cannot attach the bus");
    const int r = sd_event_loop(raw_event);
    sd_bus_detach_event(bus);
    check(r, "event loop failed");
    return r;
}

} // namespace caracara::ctl
