// ScanBus on org.caracara.Vehicle1: runs the daemon's BusScan and replies when it ends, with the
// devices that answered and a verdict per configured thruster, or the error that refused or
// ended it (through the one error map, dbus/error_reply).
#pragma once

#include "daemon/commissioning/bus_scan.hpp"
#include "drivers/sdbus/sdbus.hpp"

namespace caracara::dbus {

// The method's handler body: always 1 (the reply is sent later).
int scan_bus(sd_bus_message* call, BusScan& scan);

} // namespace caracara::dbus
