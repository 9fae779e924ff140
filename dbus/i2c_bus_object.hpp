// /org/caracara/Vehicle1/bus, org.caracara.Vehicle1.Bus: the I2C bus, its errors and recoveries.
#pragma once

#include "daemon/bus/bus_monitor.hpp"
#include "dbus/announced_object.hpp"

#include <string>

namespace caracara::dbus {

class I2cBusObject {
public:
    I2cBusObject(sd_bus* bus, BusMonitor& monitor);
    int start() { return object_.start(); }
    // The properties of the changes whose values moved since they were last announced.
    void announce(uint32_t changes) { object_.announce(changes, AnnouncedObject::When::Changed); }
    void emit_lost(const std::string& reason);
    void emit_restored(uint32_t pulses, double milliseconds);

private:
    AnnouncedObject object_;
};

} // namespace caracara::dbus
