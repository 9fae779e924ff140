// org.caracara.Simulator1: inspection and fault injection over D-Bus, so tests observe the
// hardware side independently of what caracarad claims.
//   /org/caracara/Simulator1              org.caracara.Simulator1 (bus, wire log, timing)
//   /org/caracara/Simulator1/thruster/N   org.caracara.Simulator1.Thruster
//   /org/caracara/Simulator1/teensy       org.caracara.Simulator1.Teensy
// The interface is documented in sim/org.caracara.Simulator1.xml; each object's table is in
// its own sim/inspect_*.cpp.
#pragma once

#include "drivers/sdbus/sdbus.hpp"
#include "sim/vehicle.hpp"

#include <vector>

namespace caracara::sim {

class DeviceServer;

inline constexpr const char* kInspectRoot = "/org/caracara/Simulator1";
inline constexpr const char* kInspectInvalid = "org.caracara.Simulator1.Error.InvalidArgument";

// Replies to `call` with what `fill(reply)` appends (a negative return is the failure).
template <class Fill>
int reply_with(sd_bus_message* call, Fill fill) {
    sd_bus_message* reply = nullptr;
    int r = sd_bus_message_new_method_return(call, &reply);
    if (r < 0)
        return r;
    dbus::MessagePtr guard(reply);
    if ((r = fill(reply)) < 0)
        return r;
    return sd_bus_send(nullptr, reply, nullptr);
}

class Inspector {
public:
    Inspector(sd_bus* bus, SimVehicle& vehicle, DeviceServer& server) : bus_(bus), vehicle_(vehicle), server_(server) {}
    int start(); // registers objects and requests the name; -errno

    SimVehicle& vehicle() { return vehicle_; }
    DeviceServer& server() { return server_; }

private:
    int add(const std::string& path, const char* iface, const sd_bus_vtable* vtable, void* userdata);

    sd_bus* bus_;
    SimVehicle& vehicle_;
    DeviceServer& server_;
    std::vector<dbus::SlotPtr> slots_;
};

} // namespace caracara::sim
