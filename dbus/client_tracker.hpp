// Tells the Vehicle when a client leaves the bus (NameOwnerChanged for a unique name), so a
// controlling client that vanishes stops commanding the thrusters, and the last pilot gone is
// the pilot-lost failsafe's.
#pragma once

#include "daemon/vehicle/vehicle.hpp"
#include "drivers/sdbus/sdbus.hpp"

namespace caracara::dbus {

class ClientTracker {
public:
    ClientTracker(sd_bus* bus, Vehicle& vehicle) : bus_(bus), vehicle_(vehicle) {}
    int start();

private:
    static int on_name_owner_changed(sd_bus_message* m, void* userdata, sd_bus_error*);

    sd_bus* bus_;
    Vehicle& vehicle_;
    SlotPtr slot_;
};

} // namespace caracara::dbus
