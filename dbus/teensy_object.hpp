// /org/caracara/Vehicle1/teensy, org.caracara.Vehicle1.Teensy: the wheels, servos and sensors
// behind the Teensy, and its SPI link.
#pragma once

#include "daemon/teensy/teensy_port.hpp"
#include "dbus/announced_object.hpp"

namespace caracara::dbus {

class TeensyObject {
public:
    TeensyObject(sd_bus* bus, TeensyPort& teensy);
    int start() { return object_.start(); }
    // The properties of the changes whose values moved since they were last announced.
    void announce(uint32_t changes) { object_.announce(changes, AnnouncedObject::When::Changed); }

private:
    AnnouncedObject object_;
};

} // namespace caracara::dbus
