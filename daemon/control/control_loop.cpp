#include "daemon/control/control_loop.hpp"

#include "core/clock.hpp"
#include "drivers/platform/io_error.hpp"

#include <algorithm>

namespace caracara {

namespace {
constexpr uint64_t kTelemetryPeriodNs = 200'000'000; // 5 Hz of PropertiesChanged
constexpr uint32_t kBackstopRateHz = 50;              // the tick at loop rate 0
} // namespace

ControlLoop::ControlLoop(sd_event* event, const ControlSettings& settings, Vehicle& vehicle, ThrusterBus& bus,
                         TeensyPort& teensy, SafetyLines& lines, VehicleEvents& events)
    : event_(event),
      settings_(settings),
      vehicle_(vehicle),
      bus_(bus),
      lines_(lines),
      events_(events),
      work_(event, bus, teensy, lines, [this] { end_cycle(); }, [this] { resumed(); }, [this] { orders_out(true); }) {}

std::string ControlLoop::start() {
    if (std::string e = work_.start(); !e.empty())
        return e;
    // At loop rate 0 the tick is a backstop: cycles follow each other at once, but while the
    // bus is being recovered there is nothing to clock out and the tick paces them.
    sd_event_source* s = nullptr;
    uint64_t now_us = 0;
    sd_event_now(event_, CLOCK_MONOTONIC, &now_us);
    // Accuracy 1 us: 0 would mean sd-event's default of 250 ms and a 4 Hz "50 Hz" loop.
    if (int r = sd_event_add_time(event_, &s, CLOCK_MONOTONIC, now_us, 1, on_tick, this); r < 0)
        return "sd_event_add_time: " + errno_name(-r);
    tick_source_.reset(s);
    sd_event_source_set_enabled(s, SD_EVENT_ON);
    started_ = true;
    last_cycle_ns_ = monotonic_ns();
    cycle();
    return {};
}

void ControlLoop::stop() {
    orders_out(false);
    started_ = false;
    bus_.set_results_at_tick(false); // no more ticks to take the results
    tick_source_.reset();
    work_.stop();
}

int ControlLoop::on_tick(sd_event_source* s, uint64_t usec, void* userdata) {
    auto* self = static_cast<ControlLoop*>(userdata);
    const uint32_t hz = self->settings_.loop_rate_hz;
    const uint64_t period = 1'000'000ull / (hz ? hz : kBackstopRateHz);
    // Fixed-rate schedule; after a stall skip ahead instead of bursting to catch up.
    uint64_t next = usec + period;
    uint64_t now_us = 0;
    sd_event_now(self->event_, CLOCK_MONOTONIC, &now_us);
    if (next <= now_us)
        next = now_us + period;
    sd_event_source_set_time(s, next);
    self->cycle();
    return 0;
}

void ControlLoop::end_cycle() {
    in_cycle_ = false;
    last_cycle_ns_ = monotonic_ns();
    const bool flat_out = settings_.loop_rate_hz == 0 && !bus_.monitor().recovering();
    if (flat_out || cycle_overrun_)
        work_.step_aside(); // resumed() starts the next cycle
    else
        work_.pause();
}

void ControlLoop::orders_out(bool in_flight) {
    if (in_flight == orders_in_flight_)
        return;
    orders_in_flight_ = in_flight;
    events_.orders_in_flight(in_flight);
}

void ControlLoop::bus_done(const BusJob& job) {
    if (!started_ || !bus_.worker().idle())
        return; // more of a kill's zeros to come
    orders_out(false);
    if (in_cycle_ && work_.nothing_due())
        end_cycle(); // the cycle's last transfer: closed here, not by another dispatch of the work
    else if (job.kind == BusJobKind::Order && !work_.order_due())
        work_.step_aside(); // the orders are out: announce, then the rest
    else
        work_.schedule_work();
}

void ControlLoop::resumed() {
    if (!in_cycle_ && (settings_.loop_rate_hz == 0 || cycle_overrun_)) {
        cycle_overrun_ = false;
        cycle(); // as fast as the bus allows
    } else {
        work_.schedule_work();
    }
}

void ControlLoop::cycle() {
    // The last cycle's results, taken here rather than at a wake-up of their own (may close it).
    bus_.worker().collect();
    orders_out(false); // at the latest: a dropped order (a recovery) never comes back as done
    const uint64_t t = monotonic_ns();
    lines_.poll(); // a backstop for a lost edge event
    vehicle_.tick(t);
    // The dive recorder's sample, stamped after the tick: an event the poll or the tick caused
    // is in the dive already, stamped when it happened, and a dive's time never goes back.
    events_.cycle(monotonic_ns());
    if (in_cycle_) {
        // The bus did not finish the last cycle in one period: the next one starts as soon as
        // it is done, as at loop rate 0. Refreshing the orders now instead would put them in
        // front of that cycle's status reads at every tick, and they would never be read.
        cycle_overrun_ = true;
        bus_.set_results_at_tick(false); // its end starts the next one: the loop must hear of it at once
        publish_telemetry_if_due(t);
        return;
    }
    // At a loop rate the next tick takes this cycle's results; flat out, its end starts the next.
    bus_.set_results_at_tick(settings_.loop_rate_hz != 0);
    ++cycles_;
    in_cycle_ = true;
    work_.start_cycle(settings_.status_reads_per_tick);
    publish_telemetry_if_due(t);
}

bool ControlLoop::healthy(uint64_t now_ns) const {
    const uint64_t period = settings_.loop_rate_hz ? 1'000'000'000ull / settings_.loop_rate_hz : 0;
    const uint64_t allowed = std::max<uint64_t>(1'000'000'000ull, 5 * period);
    // A bus under recovery is not an unhealthy loop: restarting the daemon would not help it.
    // A cycle that ended after `now_ns` (a time taken before it) is a healthy loop.
    return started_ && elapsed(last_cycle_ns_, now_ns) <= allowed;
}

void ControlLoop::publish_telemetry_if_due(uint64_t now_ns) {
    if (now_ns - last_telemetry_ns_ < kTelemetryPeriodNs)
        return;
    last_telemetry_ns_ = now_ns;
    events_.telemetry();
}

} // namespace caracara
