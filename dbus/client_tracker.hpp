// Tells the controller when a client leaves the bus (NameOwnerChanged for a unique name), so a
// controlling client that vanishes stops commanding the thrusters.
#pragma once

#include "daemon/controller.hpp"
#include "dbus/sdbus.hpp"

namespace caracara::dbus {

class ClientTracker {
public:
    ClientTracker(sd_bus* bus, Controller& controller) : bus_(bus), controller_(controller) {}
    int start();

private:
    static int on_name_owner_changed(sd_bus_message* m, void* userdata, sd_bus_error*);

    sd_bus* bus_;
    Controller& controller_;
    SlotPtr slot_;
};

} // namespace caracara::dbus
