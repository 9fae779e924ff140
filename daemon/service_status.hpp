// What systemd sees of the daemon: the STATUS= line (`systemctl status caracarad`), READY=1,
// STOPPING=1, and the watchdog, fed only while the control loop keeps completing cycles.
#pragma once

#include "daemon/bus/thruster_bus.hpp"
#include "daemon/control/control_loop.hpp"
#include "daemon/vehicle/vehicle.hpp"
#include "daemon/interfaces/vehicle_observer.hpp"
#include "drivers/platform/event_loop.hpp"

#include <cstdint>
#include <functional>
#include <string>

namespace caracara {

class ServiceStatus final : public VehicleObserver {
public:
    ServiceStatus(sd_event* event, const Vehicle& vehicle, const ThrusterBus& bus, const ControlLoop& loop)
        : event_(event), vehicle_(vehicle), bus_(bus), loop_(loop) {}

    void publish() const;
    // A change of state, bus, profile, faults or failsafes shows on the STATUS= line.
    void vehicle_changed(uint32_t changes) override {
        if (changes & (kChangeState | kChangeBus | kChangeProfile | kChangeFaults | kChangeFailsafes))
            publish();
    }
    // The active failsafes for the STATUS= line ("" when none).
    void set_failsafe_summary(std::function<std::string()> summary) { failsafes_ = std::move(summary); }
    // Starts feeding the watchdog if systemd asked for one (WatchdogSec=).
    void start_watchdog();
    void ready(const char* bus_name) const;
    void stopping() const;

private:
    static int on_watchdog(sd_event_source* s, uint64_t usec, void* userdata);

    sd_event* event_;
    const Vehicle& vehicle_;
    const ThrusterBus& bus_;
    const ControlLoop& loop_;
    uint64_t interval_us_ = 0;
    SourcePtr watchdog_;
    std::function<std::string()> failsafes_;
};

} // namespace caracara
