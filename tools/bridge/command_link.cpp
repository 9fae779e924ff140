#include "tools/bridge/command_link.hpp"

#include "dbus/vehicle_names.hpp"

#include <cstring>
#include <stdexcept>

namespace caracara::bridge {

namespace names = caracara::dbus;

// What a reply needs to report a refusal; freed with the call's slot (sd-bus destroy callback).
struct CommandLink::Pending {
    CommandLink* link;
    CommandKind kind;
};

CommandLink::CommandLink(boost::asio::io_context& io, const caracara::dbus::BusChoice& bus, Refused on_refused,
                         std::function<void()> on_lost)
    : on_refused_(std::move(on_refused)) {
    if (const int r = caracara::dbus::open_bus(bus, "caracara-bridge-pilot", bus_); r < 0)
        throw std::runtime_error(std::string("cannot connect to the bus: ") + std::strerror(-r));
    watch_ = std::make_unique<BusWatch>(io, bus_.get(), std::move(on_lost));
}

CommandLink::~CommandLink() {
    // Replies still pending are dropped with the connection (their slots are floating and
    // freed with the bus); the watch goes first so nothing runs while the bus closes.
    watch_.reset();
}

std::string CommandLink::unique_name() const {
    const char* name = nullptr;
    return sd_bus_get_unique_name(bus_.get(), &name) >= 0 && name ? name : "";
}

int CommandLink::on_reply(sd_bus_message* m, void* userdata, sd_bus_error*) {
    auto* p = static_cast<Pending*>(userdata);
    if (sd_bus_message_is_method_error(m, nullptr)) {
        const sd_bus_error* e = sd_bus_message_get_error(m);
        p->link->on_refused_(command_topic_name(p->kind), e && e->name ? e->name : "",
                             e && e->message ? e->message : "");
    }
    return 0;
}

void CommandLink::send(const Command& c) {
    const char* member = nullptr;
    switch (c.kind) {
    case CommandKind::Motion: member = "SetMotion"; break;
    case CommandKind::Thrust: member = "SetThrust"; break;
    case CommandKind::Kill: member = "Kill"; break;
    case CommandKind::ClearKill: member = "ClearKill"; break;
    case CommandKind::Leds: member = "SetLeds"; break;
    case CommandKind::Profile: member = "SetProfile"; break;
    }
    sd_bus_message* raw = nullptr;
    int r = sd_bus_message_new_method_call(bus_.get(), &raw, names::kBusName, names::kRootPath, names::kVehicleIface,
                                           member);
    caracara::dbus::MessagePtr call(raw);
    if (r >= 0)
        r = sd_bus_message_set_auto_start(call.get(), 0);
    if (r >= 0) {
        switch (c.kind) {
        case CommandKind::Motion:
            r = sd_bus_message_append(call.get(), "dddddd", c.axes[0], c.axes[1], c.axes[2], c.axes[3], c.axes[4],
                                      c.axes[5]);
            break;
        case CommandKind::Thrust:
            r = sd_bus_message_append_array(call.get(), 'i', c.thrust.data(), c.thrust.size() * sizeof(int32_t));
            break;
        case CommandKind::Leds: r = sd_bus_message_append(call.get(), "yyy", c.rgb[0], c.rgb[1], c.rgb[2]); break;
        case CommandKind::Profile: r = sd_bus_message_append(call.get(), "s", c.profile.c_str()); break;
        case CommandKind::Kill:
        case CommandKind::ClearKill: break;
        }
    }
    auto* pending = new Pending{this, c.kind};
    sd_bus_slot* slot = nullptr;
    if (r >= 0)
        r = sd_bus_call_async(bus_.get(), &slot, call.get(), on_reply, pending, 0);
    if (r < 0) {
        delete pending;
        on_refused_(command_topic_name(c.kind), "org.caracara.Bridge.Error.SendFailed", std::strerror(-r));
        return;
    }
    // The slot floats (the bus owns it: freed after the reply or with the bus) and frees
    // `pending` with it; the reference sd_bus_call_async gave us is dropped.
    sd_bus_slot_set_destroy_callback(slot, [](void* p) { delete static_cast<Pending*>(p); });
    sd_bus_slot_set_floating(slot, 1);
    sd_bus_slot_unref(slot);
    watch_->kick();
}

} // namespace caracara::bridge
