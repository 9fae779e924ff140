// The bus work of the control loop's cycles, from its StandingOrders (the order schedule and
// the orders standing now). Runs below D-Bus: each I2C transfer is handed to the bus worker's
// thread (one at a time, so a new command's order is next in line) and the loop goes on
// serving D-Bus, the kill switch and the timers while it is on the wire. The work steps
// aside after each burst of orders and at the end of a cycle, so what is below it (the
// announcements) runs even when the bus never rests. ControlLoop says when a cycle starts.
#pragma once

#include "daemon/bus/thruster_bus.hpp"
#include "daemon/control/standing_orders.hpp"
#include "daemon/safety/safety_lines.hpp"
#include "daemon/teensy/teensy_port.hpp"
#include "daemon/interfaces/demand_listener.hpp"
#include "daemon/interfaces/input_probe.hpp"
#include "drivers/platform/event_loop.hpp"

#include <cstdint>
#include <functional>
#include <string>

namespace caracara {

// D-Bus, timers and the kill switch run at SD_EVENT_PRIORITY_NORMAL or above; the bus work
// below them; announcements (PropertiesChanged) below the work, so that neither an order nor
// the reply of the call that caused the change waits for one.
inline constexpr int64_t kWorkPriority = SD_EVENT_PRIORITY_NORMAL + 10;
inline constexpr int64_t kAnnouncePriority = kWorkPriority + 1;

class BusWorkDispatch final {
public:
    // `cycle_work_done`: nothing is due and the bus is idle (the cycle can close);
    // `resumed`: the work stepped aside and what is below it ran; `command_handed_over`: a
    // command's changed orders are all handed to the bus worker.
    BusWorkDispatch(sd_event* event, ThrusterBus& bus, TeensyPort& teensy, SafetyLines& lines,
                    std::function<void()> cycle_work_done, std::function<void()> resumed,
                    std::function<void()> command_handed_over);

    std::string start(); // "" or why the sources could not be made
    void stop();
    void set_input_probe(const InputProbe* p) { input_ = p; }

    // A cycle's work (every order refreshed, `status_reads` status reads, the Teensy's slot),
    // handed to the bus worker right away.
    void start_cycle(uint32_t status_reads);
    // There is bus work due: run it soon, unless the work has stepped aside, in which case
    // it resumes right after the announcements.
    void schedule_work();
    // Off until schedule_work(), after what is below the work (the announcements).
    void step_aside();
    void pause(); // off until schedule_work()
    bool order_due() const { return orders_.order_due(); }
    bool nothing_due() const { return orders_.nothing_due(); }

    void demand_changed(const MotorValues& orders);
    void zero_all(ZeroOrder where) { orders_.zero_all(where); }
    void resend_orders() { orders_.resend(); }

private:
    // Transfer: handed to the bus worker; Waiting: the worker still has one; Other: done here.
    enum class Work { None, Transfer, Waiting, Other };
    static int on_work(sd_event_source*, void* userdata);
    static int on_resume(sd_event_source*, void* userdata);
    Work work_one();
    bool input_pending() const;

    sd_event* event_;
    ThrusterBus& bus_;
    TeensyPort& teensy_;
    SafetyLines& lines_;
    std::function<void()> cycle_work_done_;
    std::function<void()> resumed_;
    std::function<void()> command_handed_over_;
    const InputProbe* input_ = nullptr;

    StandingOrders orders_;
    bool command_out_ = false; // changed orders are being handed over: the loop hears of them at once

    SourcePtr work_source_;
    SourcePtr resume_source_; // below the announcements: the rest of the work, or the next cycle at rate 0
};

} // namespace caracara
