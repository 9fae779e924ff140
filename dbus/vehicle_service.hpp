// org.caracara.Vehicle1 on D-Bus: translates calls into Controller methods and controller
// changes into PropertiesChanged. No policy lives here; the contract is the XML files beside
// this header.
#pragma once

#include "daemon/vehicle_daemon.hpp"
#include "dbus/sdbus.hpp"
#include "dbus/vehicle_names.hpp"

#include <array>
#include <string>
#include <vector>

namespace caracara::dbus {

class VehicleService final : public VehicleObserver {
public:
    VehicleService(sd_bus* bus, VehicleDaemon& controller) : bus_(bus), controller_(controller) {}
    ~VehicleService() override;
    // Registers the objects and the client-tracking match, then requests the bus name.
    int start();

    void vehicle_changed(uint32_t changes) override;
    void telemetry() override;
    void bus_lost(const std::string& reason) override;
    void bus_restored(uint32_t pulses, double milliseconds) override;

    VehicleDaemon& controller() { return controller_; }
    sd_bus* bus() { return bus_; }

    struct ThrusterObject {
        VehicleService* service;
        size_t index;
        std::string path;
    };

private:
    struct ThrusterSnapshot {
        bool online = false;
        int32_t ordered_value = 0;
        uint8_t ordered_speed = 0, actual_speed = 0, firmware = 0;
        double current = 0, temperature = 0;
        uint8_t faults = 0;
        uint64_t orders = 0, failures = 0, reads = 0, nacks = 0, timeouts = 0, bad = 0;
        std::string last_error;
        bool operator==(const ThrusterSnapshot&) const = default;
    };
    ThrusterSnapshot snapshot(size_t i) const;
    void emit_bus_changes();
    void emit_vehicle_changes(uint32_t changes);
    void emit_telemetry();
    void announce(uint32_t changes, bool telemetry);
    static int on_flush(sd_event_source*, void* userdata);
    uint32_t pending_ = 0;
    bool telemetry_pending_ = false;
    uint64_t publications_ = 0;
    bool counters_due_ = true;
    SourcePtr flush_;
    static int on_name_owner_changed(sd_bus_message* m, void* userdata, sd_bus_error*);

    sd_bus* bus_;
    VehicleDaemon& controller_;
    std::vector<SlotPtr> slots_;
    std::vector<std::unique_ptr<ThrusterObject>> thruster_objects_;
    std::vector<ThrusterSnapshot> published_;
    TeensyTelemetry published_teensy_;
    BusTelemetry published_bus_;
    uint64_t published_teensy_frames_ = 0, published_teensy_busy_ = 0, published_teensy_errors_ = 0;
};

} // namespace caracara::dbus
