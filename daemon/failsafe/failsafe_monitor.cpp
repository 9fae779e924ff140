#include "daemon/failsafe/failsafe_monitor.hpp"

#include "core/clock.hpp"
#include "drivers/platform/io_error.hpp"

#include <algorithm>
#include <utility>

namespace caracara {

FailsafeMonitor::FailsafeMonitor(sd_event* event, const FailsafeSettings& settings, std::size_t thrusters,
                                 Readings readings, Vehicle& vehicle, VehicleEvents& events)
    : event_(event), settings_(settings), thrusters_(thrusters), readings_(std::move(readings)), vehicle_(vehicle),
      events_(events), policy_(settings, thrusters), report_(settings, events), ascent_(settings.surface, vehicle, events),
      clearance_(policy_, vehicle, events),
      period_us_(std::max<uint64_t>(1000, std::min(kPeriodNs, vehicle.readings().safety().config().command_timeout_ns / 2)) /
                 1000) {}

std::string FailsafeMonitor::start() {
    sd_event_source* s = nullptr;
    if (int r = sd_event_add_time_relative(event_, &s, CLOCK_MONOTONIC, period_us_, 1000, on_timer, this); r < 0)
        return "sd_event_add_time_relative: " + errno_name(-r);
    timer_.reset(s);
    sd_event_source_set_enabled(s, SD_EVENT_ON);
    sd_event_source* d = nullptr;
    if (int r = sd_event_add_defer(event_, &d, on_deferred, this); r < 0)
        return "sd_event_add_defer: " + errno_name(-r);
    deferred_.reset(d);
    // Ahead of everything else the loop has ready: it is a kill waiting.
    sd_event_source_set_priority(d, SD_EVENT_PRIORITY_IMPORTANT);
    sd_event_source_set_enabled(d, SD_EVENT_OFF);
    started_ = true;
    // What already holds (a fitted Teensy absent at start) kills now, not at the first reading.
    decide({}, monotonic_ns(), false);
    return {};
}

int FailsafeMonitor::on_timer(sd_event_source* s, uint64_t usec, void* userdata) {
    auto* self = static_cast<FailsafeMonitor*>(userdata);
    sd_event_source_set_time(s, usec + self->period_us_);
    self->poll(monotonic_ns());
    return 0;
}

int FailsafeMonitor::on_deferred(sd_event_source*, void* userdata) {
    static_cast<FailsafeMonitor*>(userdata)->decide({}, monotonic_ns(), false);
    return 0;
}

void FailsafeMonitor::push(FailsafeCondition c, bool holds, std::string_view reason) {
    if (holds)
        reasons_[static_cast<std::size_t>(c)] = reason;
    pushed_.push_back({c, holds});
    if (!started_)
        return; // decided at start
    // Inside a decision, whose kill is under way (the kill output lost as it was asserted, the
    // pilots forgotten by the kill), or inside another of the Vehicle's sequences (a ClearKill's
    // or a D-Bus Kill's line write failed): never halfway through it, but as soon as it returns
    // to the loop; a condition that cleared during a decision (the pilots its kill forgot) at the
    // next reading, as the thruster conditions do, so that the raised failsafe is announced first.
    if (deciding_ || vehicle_.acting()) {
        if ((holds || !deciding_) && deferred_)
            sd_event_source_set_enabled(deferred_.get(), SD_EVENT_ONESHOT);
        return;
    }
    decide({}, monotonic_ns(), false);
}

void FailsafeMonitor::poll(uint64_t now) {
    FailsafeTransitions ts;
    for (std::size_t i = 0; i < thrusters_ && i < kMotorCount; ++i) {
        // A reading seen already changes nothing in the policy (a condition's persistence runs
        // on in its tick): a status reply comes every few cycles, the poll at 20 Hz.
        const auto r = readings_(i);
        if (!r || r == observed_[i])
            continue;
        observed_[i] = r;
        FailsafeTransitions t = policy_.observe(i, r->fault_bits, r->temperature_c, now);
        ts.insert(ts.end(), t.begin(), t.end());
    }
    decide(std::move(ts), now, true);
}

void FailsafeMonitor::decide(FailsafeTransitions ts, uint64_t now, bool keep_ascent) {
    if (deciding_)
        return;
    deciding_ = true;
    for (const Pushed& p : std::exchange(pushed_, {})) {
        FailsafeTransitions t = policy_.set_condition(p.condition, p.holds, now);
        ts.insert(ts.end(), t.begin(), t.end());
    }
    FailsafeTransitions due = policy_.tick(now);
    ts.insert(ts.end(), due.begin(), due.end());
    const uint64_t kill_at = policy_.pending_deadline(FailsafeCondition::PilotLost);
    if (const uint64_t at = kill_at == FailsafePolicy::kNoDeadline ? 0 : kill_at; at != pilot_lost_kill_at_) {
        pilot_lost_kill_at_ = at; // PilotLostKillAt: on its change only, not at every reading
        events_.changed(kChangeFailsafes);
    }
    report_.tell(ts);
    carry_out(ts, now);
    if (keep_ascent)
        ascent_.keep(now);
    deciding_ = false;
}

void FailsafeMonitor::carry_out(const FailsafeTransitions& ts, uint64_t now) {
    std::array<bool, kMotorCount> excluded{};
    for (std::size_t i = 0; i < thrusters_ && i < kMotorCount; ++i)
        excluded[i] = policy_.excluded(i);
    if (excluded != excluded_) {
        excluded_ = excluded;
        vehicle_.motors().exclude(excluded);
    }
    for (const FailsafeTransition& t : ts) {
        if (!t.raised)
            continue;
        const FailsafeAction a = t.failsafe.effective();
        if (a == FailsafeAction::Kill) {
            // Read as the source's own kill where the row names one ("bus", "device", "switch"),
            // with the reason it pushed; else as the failsafe's.
            const KillSource source = failsafe_row(t.failsafe.condition).kill_source;
            const std::string& pushed = reasons_[static_cast<std::size_t>(t.failsafe.condition)];
            vehicle_.kill(source, source == KillSource::Failsafe || pushed.empty() ? FailsafeReport::describe(t.failsafe)
                                                                                    : pushed);
        } else if (a == FailsafeAction::Surface && !ascent_.active()) {
            ascent_.begin(FailsafeReport::describe(t.failsafe), now);
        }
    }
}

std::string FailsafeMonitor::summary() const {
    std::string s;
    for (const ActiveFailsafe& f : policy_.active())
        s += (s.empty() ? "" : ", ") + FailsafeReport::describe(f);
    return s;
}

} // namespace caracara
