// org.caracara.Simulator1: inspection and fault injection over D-Bus, so tests observe the
// hardware side independently of what caracarad claims.
//   /org/caracara/Simulator1              org.caracara.Simulator1 (bus, wire log, timing)
//   /org/caracara/Simulator1/thruster/N   org.caracara.Simulator1.Thruster
//   /org/caracara/Simulator1/teensy       org.caracara.Simulator1.Teensy
// The interface is documented in sim/org.caracara.Simulator1.xml; each object's table is in
// its own sim/inspect_*.cpp.
#pragma once

#include "drivers/sdbus/sdbus.hpp"
#include "sim/simulator_parts.hpp"

#include <string>
#include <vector>

namespace caracara::sim {

class Inspector {
public:
    Inspector(sd_bus* bus, SimVehicle& vehicle, DeviceServer& server) : bus_(bus), parts_{vehicle, server} {}
    int start(); // registers objects and requests the name; -errno

private:
    int add(const std::string& path, const char* iface, const sd_bus_vtable* vtable, void* userdata);

    sd_bus* bus_;
    SimulatorParts parts_;
    std::vector<dbus::SlotPtr> slots_;
};

} // namespace caracara::sim
