// /org/caracara/Vehicle1, org.caracara.Vehicle1: commands in, vehicle state out.
#pragma once

#include "daemon/vehicle_daemon.hpp"
#include "dbus/announced_object.hpp"

namespace caracara::dbus {

class VehicleObject {
public:
    VehicleObject(sd_bus* bus, VehicleDaemon& daemon);
    int start() { return object_.start(); }
    // Every property of the changes, changed or not: a command that sets the same values again
    // is still announced.
    void announce(uint32_t changes) { object_.announce(changes, AnnouncedObject::When::Always); }
    // The Failsafe signal: one raised.
    void emit_failsafe(const ActiveFailsafe& f);

private:
    AnnouncedObject object_;
};

} // namespace caracara::dbus
