// Thin RAII over sd-bus handles (sd-event ones are in drivers/platform/event_loop.hpp), and opening the bus a program was told to use.
#pragma once

#include "drivers/platform/event_loop.hpp"

#include <memory>
#include <string>
#include <systemd/sd-bus.h>
#include <systemd/sd-event.h>

namespace caracara::dbus {

struct BusUnref { void operator()(sd_bus* b) const { sd_bus_flush_close_unref(b); } };
struct SlotUnref { void operator()(sd_bus_slot* s) const { sd_bus_slot_unref(s); } };
struct MessageUnref { void operator()(sd_bus_message* m) const { sd_bus_message_unref(m); } };

using BusPtr = std::unique_ptr<sd_bus, BusUnref>;
using SlotPtr = std::unique_ptr<sd_bus_slot, SlotUnref>;
using MessagePtr = std::unique_ptr<sd_bus_message, MessageUnref>;
using caracara::EventPtr;
using caracara::SourcePtr;

// Which bus to connect to: the system bus (default), the user's session bus, an explicit
// address such as "unix:path=/tmp/bus" (tests run a private dbus-daemon), or the system bus of
// another machine over SSH ([USER@]HOST[:PORT] in `address`; sd_bus_open_system_remote runs
// systemd-stdio-bridge there, as systemctl -H and busctl -H do).
struct BusChoice {
    enum class Kind { System, User, Address, Remote } kind = Kind::System;
    std::string address;
    std::string describe() const;
};

// Opens the chosen bus with `description` as the connection name; returns -errno.
int open_bus(const BusChoice& choice, const char* description, BusPtr& out);

} // namespace caracara::dbus
