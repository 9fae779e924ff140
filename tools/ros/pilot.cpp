#include "tools/ros/pilot.hpp"

#include "core/clock.hpp"
#include "dbus/vehicle_names.hpp"

#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace caracara::ros {

namespace names = caracara::dbus;

Pilot::Pilot(sd_event* event, const caracara::dbus::BusChoice& bus, std::string writer, CommandRecord& record,
             std::string motion_note)
    : writer_(std::move(writer)), motion_writer_(motion_note.empty() ? writer_ : writer_ + " (" + motion_note + ")"),
      record_(record) {
    if (const int r = caracara::dbus::open_bus(bus, "caracara-ros-pilot", bus_); r < 0)
        throw std::runtime_error(std::string("cannot connect to the bus: ") + std::strerror(-r));
    if (const int r = sd_bus_attach_event(bus_.get(), event, SD_EVENT_PRIORITY_NORMAL); r < 0)
        throw std::runtime_error(std::string("cannot attach the bus: ") + std::strerror(-r));
}

Pilot::~Pilot() {
    // Closing the connection is the point: the daemon zeroes this client's thrust at once.
    sd_bus_detach_event(bus_.get());
}

int Pilot::on_motion_reply(sd_bus_message* m, void* userdata, sd_bus_error*) {
    auto* self = static_cast<Pilot*>(userdata);
    self->replied(m, self->motion_writer_);
    return 0;
}

int Pilot::on_thrust_reply(sd_bus_message* m, void* userdata, sd_bus_error*) {
    auto* self = static_cast<Pilot*>(userdata);
    self->replied(m, self->writer_);
    return 0;
}

void Pilot::replied(sd_bus_message* m, const std::string& writer) {
    if (!sd_bus_message_is_method_error(m, nullptr))
        return;
    const sd_bus_error* e = sd_bus_message_get_error(m);
    const std::string name = e && e->name ? e->name : "", message = e && e->message ? e->message : "";
    std::fprintf(stderr, "caracara-ros: command from writer %s refused: %s: %s\n", writer.c_str(), name.c_str(),
                 message.c_str());
    record_.refused(writer_, refusal_of(name), name + ": " + message, monotonic_ns());
}

void Pilot::send(caracara::dbus::MessagePtr call, const char* what, sd_bus_message_handler_t reply) {
    int r = sd_bus_message_set_auto_start(call.get(), 0);
    sd_bus_slot* slot = nullptr;
    // The slot's userdata is this Pilot: the slot goes with the connection, which this Pilot owns.
    if (r >= 0)
        r = sd_bus_call_async(bus_.get(), &slot, call.get(), reply, this, 0);
    if (r < 0) {
        std::fprintf(stderr, "caracara-ros: %s from writer %s not sent: %s\n", what, writer_.c_str(), std::strerror(-r));
        return;
    }
    // The slot floats: the bus frees it after the reply or with the connection.
    sd_bus_slot_set_floating(slot, 1);
    sd_bus_slot_unref(slot);
}

void Pilot::set_motion(const std::array<double, 6>& a) {
    sd_bus_message* raw = nullptr;
    int r = sd_bus_message_new_method_call(bus_.get(), &raw, names::kBusName, names::kRootPath, names::kVehicleIface,
                                           "SetMotion");
    caracara::dbus::MessagePtr call(raw);
    if (r >= 0)
        r = sd_bus_message_append(call.get(), "dddddd", a[0], a[1], a[2], a[3], a[4], a[5]);
    if (r >= 0)
        send(std::move(call), "SetMotion", on_motion_reply);
}

void Pilot::set_thrust(const std::vector<int32_t>& v) {
    sd_bus_message* raw = nullptr;
    int r = sd_bus_message_new_method_call(bus_.get(), &raw, names::kBusName, names::kRootPath, names::kVehicleIface,
                                           "SetThrust");
    caracara::dbus::MessagePtr call(raw);
    if (r >= 0)
        r = sd_bus_message_append_array(call.get(), 'i', v.data(), v.size() * sizeof(int32_t));
    if (r >= 0)
        send(std::move(call), "SetThrust", on_thrust_reply);
}

} // namespace caracara::ros
