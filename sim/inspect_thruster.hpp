// /org/caracara/Simulator1/thruster/N, org.caracara.Simulator1.Thruster: what one simulated
// thruster received, and its faults. Userdata: the ThrusterModel.
#pragma once

#include <systemd/sd-bus.h>

namespace caracara::sim {

const sd_bus_vtable* thruster_inspection();

} // namespace caracara::sim
