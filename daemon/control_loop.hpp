// The control loop: the one owner of the order schedule and of the orders standing now (handed
// down by Vehicle as a DemandListener), and its event sources and their priorities. A tick at the loop rate starts a
// cycle (safety timeouts, every order refreshed, status reads, the Teensy's slot); the bus
// work runs below D-Bus: each I2C transfer is handed to the bus worker's thread (one at a
// time, so a new command's order is next in line) and the loop goes on serving D-Bus, the
// kill switch and the timers while it is on the wire. The work steps aside after each burst
// of orders and at the end of a cycle, so what is below it (the announcements) runs even
// when the bus never rests.
#pragma once

#include "core/config.hpp"
#include "core/order_schedule.hpp"
#include "daemon/demand_listener.hpp"
#include "daemon/input_probe.hpp"
#include "daemon/safety_lines.hpp"
#include "daemon/teensy_port.hpp"
#include "daemon/thruster_bus.hpp"
#include "daemon/vehicle.hpp"
#include "daemon/vehicle_events.hpp"
#include "drivers/platform/event_loop.hpp"

#include <cstdint>
#include <string>

namespace caracara {

// D-Bus, timers and the kill switch run at SD_EVENT_PRIORITY_NORMAL or above; the bus work
// below them; announcements (PropertiesChanged) below the work, so that neither an order nor
// the reply of the call that caused the change waits for one.
inline constexpr int64_t kWorkPriority = SD_EVENT_PRIORITY_NORMAL + 10;
inline constexpr int64_t kAnnouncePriority = kWorkPriority + 1;

class ControlLoop final : public DemandListener {
public:
    ControlLoop(sd_event* event, const ControlSettings& settings, Vehicle& vehicle, ThrusterBus& bus,
                TeensyPort& teensy, SafetyLines& lines, VehicleEvents& events);

    std::string start(); // "" or why the sources could not be made; runs the first cycle
    void stop();
    void set_input_probe(const InputProbe* p) { input_ = p; }
    // There is bus work due (a new command's orders): run it soon, unless the work has
    // stepped aside, in which case it resumes right after the announcements.
    void schedule_work();
    // A transfer handed to the bus worker is over (ThrusterBus's done callback).
    void bus_done(const BusJob& job);

    // Marks due at once the orders that changed or are not on the wire: they go out now, one
    // transaction per loop iteration, not at the next tick; an unchanged one is refreshed by it.
    void demand_changed(const MotorValues& orders) override;
    void zero_all(ZeroOrder where) override;
    // Every thruster's standing order, now: a recovered bus (BusRecovery) does not know what
    // the thrusters were last told.
    void resend_orders();

    uint64_t cycles() const { return cycles_; }
    // Healthy = a cycle completed recently (fed to the systemd watchdog).
    bool healthy(uint64_t now_ns) const;

private:
    // Transfer: handed to the bus worker; Waiting: the worker still has one; Other: done here.
    enum class Work { None, Transfer, Waiting, Other };
    static int on_tick(sd_event_source*, uint64_t usec, void* userdata);
    static int on_work(sd_event_source*, void* userdata);
    static int on_resume(sd_event_source*, void* userdata);
    void cycle();
    void end_cycle();
    Work work_one();
    bool input_pending() const;
    void step_aside();
    void publish_telemetry_if_due(uint64_t now_ns);

    sd_event* event_;
    const ControlSettings& settings_;
    Vehicle& vehicle_;
    ThrusterBus& bus_;
    TeensyPort& teensy_;
    SafetyLines& lines_;
    VehicleEvents& events_;
    const InputProbe* input_ = nullptr;

    OrderSchedule schedule_;
    MotorValues orders_{}; // what each thruster is to be ordered (Vehicle's last demand_changed)

    SourcePtr tick_source_;
    SourcePtr work_source_;
    SourcePtr resume_source_; // below the announcements: the rest of the work, or the next cycle at rate 0
    bool started_ = false;
    bool in_cycle_ = false;
    bool cycle_overrun_ = false; // a tick came while a cycle was still going
    uint64_t cycles_ = 0;
    uint64_t last_cycle_ns_ = 0;
    uint64_t last_telemetry_ns_ = 0;
};

} // namespace caracara
