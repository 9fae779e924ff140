// org.caracara.Simulator1: inspection and fault injection over D-Bus, so tests observe the
// hardware side independently of what caracarad claims.
//   /org/caracara/Simulator1              org.caracara.Simulator1 (bus, wire log, timing)
//   /org/caracara/Simulator1/thruster/N   org.caracara.Simulator1.Thruster
// The interface is documented in sim/org.caracara.Simulator1.xml.
#pragma once

#include "dbus/sdbus.hpp"
#include "sim/vehicle.hpp"

#include <vector>

namespace caracara::sim {

class DeviceServer;

class Inspector {
public:
    Inspector(sd_bus* bus, SimVehicle& vehicle, DeviceServer& server) : bus_(bus), vehicle_(vehicle), server_(server) {}
    int start(); // registers objects and requests the name; -errno

    SimVehicle& vehicle() { return vehicle_; }
    DeviceServer& server() { return server_; }

private:
    sd_bus* bus_;
    SimVehicle& vehicle_;
    DeviceServer& server_;
    std::vector<dbus::SlotPtr> slots_;
};

} // namespace caracara::sim
