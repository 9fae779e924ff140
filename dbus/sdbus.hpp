// Thin RAII over sd-bus / sd-event handles, and opening the bus a program was told to use.
#pragma once

#include <memory>
#include <string>
#include <systemd/sd-bus.h>
#include <systemd/sd-event.h>

namespace caracara::dbus {

struct BusUnref { void operator()(sd_bus* b) const { sd_bus_flush_close_unref(b); } };
struct SlotUnref { void operator()(sd_bus_slot* s) const { sd_bus_slot_unref(s); } };
struct MessageUnref { void operator()(sd_bus_message* m) const { sd_bus_message_unref(m); } };
struct EventUnref { void operator()(sd_event* e) const { sd_event_unref(e); } };
struct SourceUnref { void operator()(sd_event_source* s) const { sd_event_source_disable_unref(s); } };

using BusPtr = std::unique_ptr<sd_bus, BusUnref>;
using SlotPtr = std::unique_ptr<sd_bus_slot, SlotUnref>;
using MessagePtr = std::unique_ptr<sd_bus_message, MessageUnref>;
using EventPtr = std::unique_ptr<sd_event, EventUnref>;
using SourcePtr = std::unique_ptr<sd_event_source, SourceUnref>;

// Which bus to connect to: the system bus (default), the user's session bus, or an explicit
// address such as "unix:path=/tmp/bus" (tests run a private dbus-daemon).
struct BusChoice {
    enum class Kind { System, User, Address } kind = Kind::System;
    std::string address;
    std::string describe() const;
};

// Opens the chosen bus with `description` as the connection name; returns -errno.
int open_bus(const BusChoice& choice, const char* description, BusPtr& out);

} // namespace caracara::dbus
