// /org/caracara/Vehicle1/thruster/N, org.caracara.Vehicle1.Thruster: one thruster's settings,
// status and counters.
#pragma once

#include "daemon/bus/thruster_bus.hpp"
#include "dbus/announced_object.hpp"

namespace caracara::dbus {

class ThrusterObject {
public:
    ThrusterObject(sd_bus* bus, const ThrusterBus& thrusters, size_t index);
    int start() { return object_.start(); }
    // The properties of the changes whose values moved since they were last announced.
    void announce(uint32_t changes) { object_.announce(changes, AnnouncedObject::When::Changed); }

    // What the properties read from the daemon.
    size_t index() const { return index_; }
    const ThrusterDriver& driver() const { return thrusters_.thruster(index_); }
    int32_t ordered_value() const { return thrusters_.ordered_value(index_); }

private:
    const ThrusterBus& thrusters_;
    size_t index_;
    AnnouncedObject object_;
};

} // namespace caracara::dbus
