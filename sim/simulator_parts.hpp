// What the org.caracara.Simulator1 object shows: the simulated vehicle and the device server
// the daemon talks to (its userdata).
#pragma once

#include "sim/device_server.hpp"
#include "sim/sim_vehicle.hpp"

namespace caracara::sim {

struct SimulatorParts {
    SimVehicle& vehicle;
    DeviceServer& server;
};

} // namespace caracara::sim
