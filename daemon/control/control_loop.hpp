// The control loop: its cycles and their pacing. A tick at the loop rate starts a cycle
// (safety timeouts, the dive recorder's sample, then the cycle's bus work: every order
// refreshed, status reads, the Teensy's slot), which its BusWorkDispatch runs below D-Bus;
// the orders standing now (handed down by Vehicle as a DemandListener) go to it too.
#pragma once

#include "core/config.hpp"
#include "daemon/control/bus_work_dispatch.hpp"
#include "daemon/bus/thruster_bus.hpp"
#include "daemon/safety/safety_lines.hpp"
#include "daemon/teensy/teensy_port.hpp"
#include "daemon/interfaces/demand_listener.hpp"
#include "daemon/interfaces/input_probe.hpp"
#include "daemon/vehicle/vehicle.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "drivers/platform/event_loop.hpp"

#include <cstdint>
#include <string>

namespace caracara {

class ControlLoop final : public DemandListener {
public:
    ControlLoop(sd_event* event, const ControlSettings& settings, Vehicle& vehicle, ThrusterBus& bus,
                TeensyPort& teensy, SafetyLines& lines, VehicleEvents& events);

    std::string start(); // "" or why the sources could not be made; runs the first cycle
    void stop();
    void set_input_probe(const InputProbe* p) { work_.set_input_probe(p); }
    // A transfer handed to the bus worker is over (ThrusterBus's done callback).
    void bus_done(const BusJob& job);

    // Marks due at once the orders that changed or are not on the wire: they go out now, one
    // transaction per loop iteration, not at the next tick; an unchanged one is refreshed by it.
    void demand_changed(const MotorValues& orders) override { work_.demand_changed(orders); }
    void zero_all(ZeroOrder where) override { work_.zero_all(where); }
    // Every thruster's standing order, now: a recovered bus (BusRecovery) does not know what
    // the thrusters were last told.
    void resend_orders() { work_.resend_orders(); }

    uint64_t cycles() const { return cycles_; }
    // Healthy = a cycle completed recently (fed to the systemd watchdog).
    bool healthy(uint64_t now_ns) const;

private:
    static int on_tick(sd_event_source*, uint64_t usec, void* userdata);
    void cycle();
    void end_cycle();
    void resumed();
    void publish_telemetry_if_due(uint64_t now_ns);
    // A command's orders handed to the bus worker / all on the wire (told to the presentation).
    void orders_out(bool in_flight);

    sd_event* event_;
    const ControlSettings& settings_;
    Vehicle& vehicle_;
    ThrusterBus& bus_;
    SafetyLines& lines_;
    VehicleEvents& events_;
    BusWorkDispatch work_;

    SourcePtr tick_source_;
    bool started_ = false;
    bool in_cycle_ = false;
    bool cycle_overrun_ = false; // a tick came while a cycle was still going
    bool orders_in_flight_ = false;
    uint64_t cycles_ = 0;
    uint64_t last_cycle_ns_ = 0;
    uint64_t last_telemetry_ns_ = 0;
};

} // namespace caracara
