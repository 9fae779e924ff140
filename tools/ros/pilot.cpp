#include "tools/ros/pilot.hpp"

#include "core/clock.hpp"

#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace caracara::ros {

Pilot::Pilot(sd_event* event, const caracara::dbus::BusChoice& bus, std::string writer, CommandRecord& record,
             std::string motion_note)
    : writer_(std::move(writer)), motion_writer_(motion_note.empty() ? writer_ : writer_ + " (" + motion_note + ")"),
      record_(record), connection_(bus, "caracara-ros-pilot") {
    if (const int r = sd_bus_attach_event(connection_.bus(), event, SD_EVENT_PRIORITY_NORMAL); r < 0)
        throw std::runtime_error(std::string("cannot attach the bus: ") + std::strerror(-r));
}

Pilot::~Pilot() {
    // Closing the connection is the point: the daemon zeroes this client's thrust at once.
    sd_bus_detach_event(connection_.bus());
}

void Pilot::replied(const client::PilotConnection::Reply& reply, const std::string& writer, const char* what) {
    if (reply.ok())
        return;
    if (reply.error_name == client::PilotConnection::kSendFailed) {
        std::fprintf(stderr, "caracara-ros: %s from writer %s not sent: %s\n", what, writer_.c_str(),
                     reply.error_message.c_str());
        return;
    }
    std::fprintf(stderr, "caracara-ros: command from writer %s refused: %s: %s\n", writer.c_str(),
                 reply.error_name.c_str(), reply.error_message.c_str());
    record_.refused(writer_, refusal_of(reply.error_name), reply.error_name + ": " + reply.error_message, monotonic_ns());
}

void Pilot::set_motion(const std::array<double, 6>& a) {
    connection_.call(
        "SetMotion", [&](sd_bus_message* m) { return sd_bus_message_append(m, "dddddd", a[0], a[1], a[2], a[3], a[4], a[5]); },
        [this](const client::PilotConnection::Reply& r) { replied(r, motion_writer_, "SetMotion"); });
}

void Pilot::set_thrust(const std::vector<int32_t>& v) {
    connection_.call(
        "SetThrust", [&](sd_bus_message* m) { return sd_bus_message_append_array(m, 'i', v.data(), v.size() * sizeof(int32_t)); },
        [this](const client::PilotConnection::Reply& r) { replied(r, writer_, "SetThrust"); });
}

} // namespace caracara::ros
