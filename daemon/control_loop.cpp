#include "daemon/control_loop.hpp"

#include "core/clock.hpp"
#include "drivers/platform/io_error.hpp"

#include <algorithm>
#include <poll.h>

namespace caracara {

namespace {
constexpr uint64_t kTelemetryPeriodNs = 200'000'000; // 5 Hz of PropertiesChanged
constexpr uint32_t kBackstopRateHz = 50;              // the tick at loop rate 0
constexpr int kTransactionsPerDispatch = 32;
} // namespace

ControlLoop::ControlLoop(sd_event* event, const ControlSettings& settings, Vehicle& vehicle, ThrusterBus& bus,
                         TeensyPort& teensy, SafetyLines& lines, VehicleEvents& events)
    : event_(event),
      settings_(settings),
      vehicle_(vehicle),
      bus_(bus),
      teensy_(teensy),
      lines_(lines),
      events_(events),
      schedule_(bus.size()) {}

std::string ControlLoop::start() {
    sd_event_source* s = nullptr;
    int r = sd_event_add_defer(event_, &s, on_work, this);
    if (r < 0)
        return "sd_event_add_defer: " + errno_name(-r);
    work_source_.reset(s);
    sd_event_source_set_priority(s, kWorkPriority);
    sd_event_source_set_enabled(s, SD_EVENT_OFF);

    r = sd_event_add_defer(event_, &s, on_resume, this);
    if (r < 0)
        return "sd_event_add_defer: " + errno_name(-r);
    resume_source_.reset(s);
    sd_event_source_set_priority(s, kAnnouncePriority + 1);
    sd_event_source_set_enabled(s, SD_EVENT_OFF);

    // At loop rate 0 the tick is a backstop: cycles follow each other at once, but while the
    // bus is being recovered there is nothing to clock out and the tick paces them.
    uint64_t now_us = 0;
    sd_event_now(event_, CLOCK_MONOTONIC, &now_us);
    // Accuracy 1 us: 0 would mean sd-event's default of 250 ms and a 4 Hz "50 Hz" loop.
    r = sd_event_add_time(event_, &s, CLOCK_MONOTONIC, now_us, 1, on_tick, this);
    if (r < 0)
        return "sd_event_add_time: " + errno_name(-r);
    tick_source_.reset(s);
    sd_event_source_set_enabled(s, SD_EVENT_ON);
    started_ = true;
    last_cycle_ns_ = monotonic_ns();
    cycle();
    return {};
}

void ControlLoop::stop() {
    started_ = false;
    tick_source_.reset();
    work_source_.reset();
    resume_source_.reset();
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

bool ControlLoop::input_pending() const {
    // Something for a higher-priority source: a D-Bus message (read already, or on the
    // socket) or a kill switch edge. One poll() instead of a full event-loop iteration.
    if (!input_ || input_->queued())
        return true;
    pollfd fds[2]{{input_->fd(), POLLIN, 0}, {lines_.kill_switch_fd(), POLLIN, 0}};
    return ::poll(fds, 2, 0) != 0;
}

void ControlLoop::step_aside() {
    sd_event_source_set_enabled(work_source_.get(), SD_EVENT_OFF);
    sd_event_source_set_enabled(resume_source_.get(), SD_EVENT_ONESHOT);
}

int ControlLoop::on_work(sd_event_source*, void* userdata) {
    auto* self = static_cast<ControlLoop*>(userdata);
    // The cycle's transfers are handed to the bus worker as one batch (orders first; see
    // BusWorker::submit); the Teensy's slots run here meanwhile. The end of the batch
    // (bus_done) brings the work back to close the cycle.
    for (int n = 0; n < kTransactionsPerDispatch; ++n) {
        const Work w = self->work_one();
        if (w == Work::Transfer)
            continue;
        if (w == Work::Waiting) {
            sd_event_source_set_enabled(self->work_source_.get(), SD_EVENT_OFF);
            return 0;
        }
        if (w == Work::None) {
            self->end_cycle();
            return 0;
        }
        if (self->input_pending())
            return 0;
    }
    return 0;
}

void ControlLoop::end_cycle() {
    in_cycle_ = false;
    last_cycle_ns_ = monotonic_ns();
    const bool flat_out = settings_.loop_rate_hz == 0 && !bus_.recovering();
    if (flat_out || cycle_overrun_)
        step_aside(); // on_resume starts the next cycle
    else
        sd_event_source_set_enabled(work_source_.get(), SD_EVENT_OFF);
}

void ControlLoop::bus_done(const BusJob& job) {
    if (!started_ || !bus_.idle())
        return; // more of a kill's zeros to come
    if (job.kind == BusJobKind::Order && !schedule_.any_order_due())
        step_aside(); // the orders are out: announce, then the rest
    else if (in_cycle_ && schedule_.empty())
        end_cycle(); // the cycle's last transfer: closed here, not by another dispatch of the work
    else
        schedule_work();
}

int ControlLoop::on_resume(sd_event_source*, void* userdata) {
    auto* self = static_cast<ControlLoop*>(userdata);
    if (!self->in_cycle_ && (self->settings_.loop_rate_hz == 0 || self->cycle_overrun_)) {
        self->cycle_overrun_ = false;
        self->cycle(); // as fast as the bus allows
    } else {
        self->schedule_work();
    }
    return 0;
}

void ControlLoop::schedule_work() {
    // sd-event turns a one-shot source off before dispatching it, so "resume pending" is
    // exactly "resume source enabled": a tick or a command in between must not put the work
    // back in front of the announcements.
    int resume_pending = SD_EVENT_OFF;
    if (resume_source_)
        sd_event_source_get_enabled(resume_source_.get(), &resume_pending);
    if (work_source_ && resume_pending == SD_EVENT_OFF)
        sd_event_source_set_enabled(work_source_.get(), SD_EVENT_ON);
}

void ControlLoop::cycle() {
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
        publish_telemetry_if_due(t);
        return;
    }
    ++cycles_;
    in_cycle_ = true;
    schedule_.start_cycle(settings_.status_reads_per_tick, teensy_.is_open());
    // The cycle's transfers are handed to the bus worker right here (a few microseconds: no
    // transfer runs on this thread), not in another event-loop iteration; unless the work has
    // stepped aside for the announcements, when it resumes after them.
    // The work source stays on if it returns early (input waiting), as when dispatched.
    schedule_work();
    int work_on = SD_EVENT_OFF;
    sd_event_source_get_enabled(work_source_.get(), &work_on);
    if (work_on != SD_EVENT_OFF)
        on_work(work_source_.get(), this);
    publish_telemetry_if_due(t);
}

ControlLoop::Work ControlLoop::work_one() {
    // While the bus is closed for recovery nothing is due on it: the recovery re-sends every
    // order when it is back (resend_orders), and the next cycle marks the rest again.
    const bool bus_usable = !bus_.recovering();
    if (!bus_usable)
        schedule_.drop_bus_work();
    const OrderSchedule::Item item = schedule_.next(bus_usable);
    switch (item.kind) {
    case OrderSchedule::Kind::Order:
        bus_.send_order(item.index, orders_[item.index]);
        return Work::Transfer;
    case OrderSchedule::Kind::Status:
        bus_.read_status(item.index);
        return Work::Transfer;
    case OrderSchedule::Kind::Teensy:
        teensy_.poll();
        return Work::Other;
    case OrderSchedule::Kind::None: break;
    }
    // The cycle ends once its transfers are done too.
    return bus_.idle() ? Work::None : Work::Waiting;
}

void ControlLoop::demand_changed(const MotorValues& orders) {
    bool any_due = false;
    for (size_t i = 0; i < bus_.size() && i < kMotorCount; ++i)
        if (orders[i] != orders_[i] || bus_.ordered_value(i) != orders[i]) {
            schedule_.mark_order(i);
            any_due = true;
        }
    orders_ = orders;
    if (any_due)
        schedule_work();
}

void ControlLoop::zero_all(ZeroOrder where) {
    // Behind: a command the client had sent reaches the wire before its zeros, so a one-shot
    // `busctl call` moves the thrusters for a moment, whether or not its disconnect arrives
    // before the loop sent the orders.
    if (where == ZeroOrder::Behind)
        for (size_t i = 0; !bus_.recovering() && schedule_.pop_order(i);)
            bus_.send_order(i, orders_[i]);
    orders_.fill(0);
    schedule_.drop_orders();
    bus_.zero_all(where);
}

void ControlLoop::resend_orders() {
    for (size_t i = 0; i < bus_.size() && i < kMotorCount; ++i)
        bus_.send_order(i, orders_[i]);
}

bool ControlLoop::healthy(uint64_t now_ns) const {
    const uint64_t period = settings_.loop_rate_hz ? 1'000'000'000ull / settings_.loop_rate_hz : 0;
    const uint64_t allowed = std::max<uint64_t>(1'000'000'000ull, 5 * period);
    // A bus under recovery is not an unhealthy loop: restarting the daemon would not help it.
    return started_ && now_ns - last_cycle_ns_ <= allowed;
}

void ControlLoop::publish_telemetry_if_due(uint64_t now_ns) {
    if (now_ns - last_telemetry_ns_ < kTelemetryPeriodNs)
        return;
    last_telemetry_ns_ = now_ns;
    events_.telemetry();
}

} // namespace caracara
