#include "daemon/failsafe/failsafe_monitor.hpp"

#include "core/clock.hpp"
#include "daemon/loop/log.hpp"
#include "drivers/platform/io_error.hpp"

#include <algorithm>

namespace caracara {

FailsafeMonitor::FailsafeMonitor(sd_event* event, const FailsafeSettings& settings, std::size_t thrusters,
                                 Readings readings, Conditions conditions, Vehicle& vehicle, VehicleEvents& events)
    : event_(event), settings_(settings), thrusters_(thrusters), readings_(std::move(readings)),
      conditions_(std::move(conditions)), vehicle_(vehicle), events_(events), policy_(settings, thrusters),
      report_(settings, events), ascent_(settings.surface, vehicle, events),
      period_us_(std::max<uint64_t>(1000, std::min(kPeriodNs, vehicle.safety().config().command_timeout_ns / 2)) /
                 1000) {
    vehicle_.set_failsafe_gate(this);
}

std::string FailsafeMonitor::start() {
    sd_event_source* s = nullptr;
    if (int r = sd_event_add_time_relative(event_, &s, CLOCK_MONOTONIC, period_us_, 1000, on_timer, this); r < 0)
        return "sd_event_add_time_relative: " + errno_name(-r);
    timer_.reset(s);
    sd_event_source_set_enabled(s, SD_EVENT_ON);
    // What already holds (a fitted Teensy absent at start) kills now, not at the first reading.
    conditions_changed();
    return {};
}

int FailsafeMonitor::on_timer(sd_event_source* s, uint64_t usec, void* userdata) {
    auto* self = static_cast<FailsafeMonitor*>(userdata);
    sd_event_source_set_time(s, usec + self->period_us_);
    self->poll(monotonic_ns());
    return 0;
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
    FailsafeTransitions own = look_at_conditions(now);
    ts.insert(ts.end(), own.begin(), own.end());
    report_.tell(ts);
    carry_out(ts, now);
    ascent_.keep(now);
}

FailsafeTransitions FailsafeMonitor::look_at_conditions(uint64_t now) {
    FailsafeTransitions ts;
    const auto holding = conditions_();
    for (std::size_t c = 0; c < kFailsafeConditionCount; ++c)
        if (condition_is_fixed(static_cast<FailsafeCondition>(c))) {
            FailsafeTransitions t = policy_.set_condition(static_cast<FailsafeCondition>(c), holding[c], now);
            ts.insert(ts.end(), t.begin(), t.end());
        }
    FailsafeTransitions due = policy_.tick(now);
    ts.insert(ts.end(), due.begin(), due.end());
    const uint64_t kill_at = policy_.pending_deadline(FailsafeCondition::PilotLost);
    if (const uint64_t at = kill_at == FailsafePolicy::kNoDeadline ? 0 : kill_at; at != pilot_lost_kill_at_) {
        pilot_lost_kill_at_ = at; // PilotLostKillAt: on its change only, not at every reading
        events_.changed(kChangeFailsafes);
    }
    return ts;
}

void FailsafeMonitor::conditions_changed() {
    const uint64_t now = monotonic_ns();
    const FailsafeTransitions ts = look_at_conditions(now);
    report_.tell(ts);
    carry_out(ts, now);
}

void FailsafeMonitor::carry_out(const FailsafeTransitions& ts, uint64_t now) {
    std::array<bool, kMotorCount> excluded{};
    for (std::size_t i = 0; i < thrusters_ && i < kMotorCount; ++i)
        excluded[i] = policy_.excluded(i);
    if (excluded != excluded_) {
        excluded_ = excluded;
        vehicle_.exclude(excluded);
    }
    for (const FailsafeTransition& t : ts) {
        if (!t.raised)
            continue;
        const FailsafeAction a = t.failsafe.effective();
        if (a == FailsafeAction::Kill) {
            vehicle_.kill(KillSource::Failsafe, FailsafeReport::describe(t.failsafe));
        } else if (a == FailsafeAction::Surface && !ascent_.active()) {
            ascent_.begin(FailsafeReport::describe(t.failsafe), now);
        }
    }
}

Result FailsafeMonitor::clear_kill_refusal() const {
    // Bus lost, an unreachable thruster and the kill switch are refused where they arise, by
    // name (BusLost, ThrusterUnreachable, KillSwitchSet), and at once when they end, not at
    // this object's next reading; pilot lost ended with its kill (nothing is left to lose). The
    // Teensy link is refused here, by the failsafe that holds: no other error names it.
    std::vector<ActiveFailsafe> b = policy_.blocking();
    std::erase_if(b, [this](const ActiveFailsafe& f) {
        return (condition_is_fixed(f.condition) && f.condition != FailsafeCondition::TeensyLinkLost) ||
               (overriding_ && f.condition == *overriding_);
    });
    if (b.empty())
        return {};
    std::string m = "a failsafe holds: ";
    for (std::size_t i = 0; i < b.size(); ++i)
        m += (i ? ", " : "") + FailsafeReport::describe(b[i]);
    const auto fixed =
        std::find_if(b.begin(), b.end(), [](const ActiveFailsafe& f) { return condition_is_fixed(f.condition); });
    if (fixed != b.end())
        m += "; " + std::string(condition_name(fixed->condition)) + " is fixed at kill: ClearKill works once it clears";
    else
        m += "; ClearKillOverride(\"" + std::string(condition_name(b.front().condition)) +
             "\") clears the kill anyway";
    return {Status::FailsafeActive, m};
}

Result FailsafeMonitor::clear_kill_override(std::string_view condition, std::string_view caller) {
    const auto c = condition_from_name(condition);
    if (!c)
        return {Status::InvalidValue, "no failsafe condition \"" + std::string(condition) + "\""};
    if (condition_is_fixed(*c))
        return {Status::FailsafeActive, std::string(condition) + " is fixed at kill: it cannot be overridden"};
    // ClearKill with the named condition's failsafes set aside (another that holds still
    // refuses); they are overridden only when it clears the kill: a refused call changes nothing.
    overriding_ = *c;
    Result r = vehicle_.clear_kill();
    overriding_.reset();
    if (!r.ok())
        return r;
    if (policy_.override_condition(*c)) {
        log_warning("FAILSAFE OVERRIDE: %s named %s in ClearKillOverride; it only warns until it clears",
                    std::string(caller).c_str(), std::string(condition).c_str());
        events_.changed(kChangeFailsafes);
    }
    return r;
}

std::string FailsafeMonitor::summary() const {
    std::string s;
    for (const ActiveFailsafe& f : policy_.active())
        s += (s.empty() ? "" : ", ") + FailsafeReport::describe(f);
    return s;
}

} // namespace caracara
