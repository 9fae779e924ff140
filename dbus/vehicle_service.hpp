// org.caracara.Vehicle1 on D-Bus: the daemon's objects, composed. Translation only: policy is
// in daemon/; the contract is the XML files beside this header.
#pragma once

#include "daemon/bus/bus_monitor.hpp"
#include "daemon/bus/thruster_bus.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "daemon/interfaces/vehicle_observer.hpp"
#include "daemon/teensy/teensy_port.hpp"
#include "dbus/announcer.hpp"
#include "dbus/client_tracker.hpp"
#include "dbus/i2c_bus_object.hpp"
#include "dbus/teensy_object.hpp"
#include "dbus/thruster_object.hpp"
#include "dbus/vehicle_names.hpp"
#include "dbus/vehicle_object.hpp"
#include "drivers/sdbus/sdbus.hpp"

#include <memory>
#include <string>
#include <vector>

namespace caracara::dbus {

class VehicleService final : public VehicleObserver {
public:
    // What the objects show and drive, handed by the composition root: the vehicle object's
    // parts, the thrusters and their bus, the Teensy, and the events whose caller it names.
    struct Parts {
        VehicleObject::Parts vehicle;
        const ThrusterBus& thrusters;
        BusMonitor& monitor;
        TeensyPort& teensy;
        VehicleEvents& events;
    };
    VehicleService(sd_bus* bus, const Parts& parts);
    ~VehicleService() override;
    // Registers the objects and the client tracking, then requests the bus name.
    int start();

    void vehicle_changed(uint32_t changes) override { announcer_.request(changes); }
    void telemetry() override { announcer_.request(kTelemetryTick); }
    void orders_in_flight(bool in_flight) override { announcer_.hold(in_flight); }
    void bus_lost(const std::string& reason) override { i2c_bus_object_.emit_lost(reason); }
    void bus_restored(uint32_t pulses, double milliseconds) override { i2c_bus_object_.emit_restored(pulses, milliseconds); }
    void failsafe(const ActiveFailsafe& f, bool raised) override {
        if (raised)
            vehicle_.emit_failsafe(f);
    }

private:
    void announce(uint32_t changes);

    sd_bus* bus_;
    VehicleEvents& events_;
    SlotPtr object_manager_;
    VehicleObject vehicle_;
    std::vector<std::unique_ptr<ThrusterObject>> thrusters_;
    TeensyObject teensy_;
    I2cBusObject i2c_bus_object_;
    ClientTracker clients_;
    Announcer announcer_; // last: gone first, before the objects it announces
};

} // namespace caracara::dbus
