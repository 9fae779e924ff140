#include "tools/client/pilot_connection.hpp"

#include "dbus/vehicle_names.hpp"

#include <cstring>
#include <memory>
#include <stdexcept>

namespace caracara::client {

namespace names = caracara::dbus;

namespace {

// The call's callback, freed with its slot (the sd-bus destroy callback).
int replied(sd_bus_message* m, void* userdata, sd_bus_error*) {
    const auto& on_reply = *static_cast<PilotConnection::OnReply*>(userdata);
    if (sd_bus_message_is_method_error(m, nullptr)) {
        const sd_bus_error* e = sd_bus_message_get_error(m);
        on_reply({m, e && e->name ? e->name : "", e && e->message ? e->message : ""});
    } else {
        on_reply({m, "", ""});
    }
    return 0;
}

} // namespace

PilotConnection::PilotConnection(const caracara::dbus::BusChoice& bus, const char* description) {
    if (const int r = caracara::dbus::open_bus(bus, description, bus_); r < 0)
        throw std::runtime_error(std::string("cannot connect to the bus: ") + std::strerror(-r));
}

std::string PilotConnection::unique_name() const {
    const char* name = nullptr;
    return sd_bus_get_unique_name(bus_.get(), &name) >= 0 && name ? name : "";
}

void PilotConnection::call(const char* member, const Append& append, OnReply on_reply,
                           std::chrono::microseconds timeout) {
    sd_bus_message* raw = nullptr;
    int r = sd_bus_message_new_method_call(bus_.get(), &raw, names::kBusName, names::kRootPath, names::kVehicleIface,
                                           member);
    caracara::dbus::MessagePtr call(raw);
    if (r >= 0)
        r = sd_bus_message_set_auto_start(call.get(), 0);
    if (r >= 0 && append)
        r = append(call.get());
    auto callback = std::make_unique<OnReply>(std::move(on_reply));
    sd_bus_slot* slot = nullptr;
    if (r >= 0)
        r = sd_bus_call_async(bus_.get(), &slot, call.get(), replied, callback.get(),
                              static_cast<uint64_t>(timeout.count()));
    if (r < 0) {
        (*callback)({nullptr, kSendFailed, std::strerror(-r)});
        return;
    }
    // The slot floats (the bus owns it: freed after the reply or with the connection) and frees
    // the callback with it; the reference sd_bus_call_async gave is dropped.
    callback.release();
    sd_bus_slot_set_destroy_callback(slot, [](void* p) { delete static_cast<OnReply*>(p); });
    sd_bus_slot_set_floating(slot, 1);
    sd_bus_slot_unref(slot);
}

} // namespace caracara::client
