// /org/caracara/Vehicle1, org.caracara.Vehicle1: commands in, vehicle state out.
#pragma once

#include "core/config.hpp"
#include "daemon/commissioning/bus_scan.hpp"
#include "daemon/commissioning/direction_detection.hpp"
#include "daemon/commissioning/motor_test.hpp"
#include "daemon/commissioning/preflight.hpp"
#include "daemon/failsafe/failsafe_monitor.hpp"
#include "daemon/teensy/teensy_port.hpp"
#include "daemon/control/control_loop.hpp"
#include "daemon/vehicle/packet_handler.hpp"
#include "daemon/vehicle/vehicle.hpp"
#include "dbus/announced_object.hpp"

namespace caracara::dbus {

class VehicleObject {
public:
    // What the object drives and shows: the vehicle, its legacy packet, the Teensy's LEDs, the loop's cycle
    // count, the control settings, the failsafes (active ones, ClearKillOverride), the motor test,
    // direction detection, the preflight and the bus scan.
    struct Parts {
        Vehicle& vehicle;
        PacketHandler& packets;
        TeensyPort& teensy;
        const ControlLoop& loop;
        const ControlSettings& control;
        FailsafeMonitor& failsafes;
        MotorTest& motor_test;
        DirectionDetection& directions;
        Preflight& preflight;
        BusScan& bus_scan;
    };
    VehicleObject(sd_bus* bus, const Parts& parts);
    VehicleObject(const VehicleObject&) = delete;
    VehicleObject& operator=(const VehicleObject&) = delete;
    int start() { return object_.start(); }
    // Every property of the changes, changed or not: a command that sets the same values again
    // is still announced.
    void announce(uint32_t changes) { object_.announce(changes, AnnouncedObject::When::Always); }
    // The Failsafe signal: one raised.
    void emit_failsafe(const ActiveFailsafe& f);

private:
    Parts parts_; // the methods' and properties' userdata
    AnnouncedObject object_;
};

} // namespace caracara::dbus
