#include "daemon/vehicle/vehicle.hpp"

#include "core/clock.hpp"
#include "core/status_of.hpp"
#include "daemon/loop/log.hpp"

namespace caracara {

static_assert(DeadlineTimer::kNever == SafetyMachine::kNoDeadline);

Vehicle::Vehicle(const DaemonConfig& config, ThrusterBus& bus, SafetyLines& lines, TeensyPort& teensy,
                 VehicleEvents& events, FailsafeGate& failsafes)
    : config_(config),
      lines_(lines),
      teensy_(teensy),
      events_(events),
      actuator_(bus, lines, teensy),
      safety_(safety_config(config), false, monotonic_ns()),
      deadline_([this] { tick(monotonic_ns()); }),
      condition_(safety_, bus, lines, failsafes),
      pilots_(config.failsafe, safety_, failsafes, [this](const SafetyAction& a) { handle(a); }),
      acceptance_(config.mixing, safety_, condition_, deadline_, events, pilots_),
      motors_(config, safety_, acceptance_, actuator_, events),
      readings_(safety_, condition_, acceptance_, motors_) {}

void Vehicle::handle(const SafetyAction& a, const Result* kill) {
    uint32_t changes = 0;
    if (a.clear_commands) {
        motors_.clear();
        changes |= kChangeMotors | kChangeController;
    }
    if (safety_.kill_output_asserted())
        acceptance_.end_surfacing(); // a kill ends an ascent at once
    // Not re-entered halfway: a line lost inside it is decided by the failsafes after it.
    const bool outer = !acting_;
    acting_ = true;
    actuator_.carry_out(a, safety_.kill_output_asserted(), kill);
    acting_ = !outer;
    if (a.state_changed)
        changes |= kChangeState;
    if (a.command_stale)
        log_info("command stream silent for %llu ms: thrusters to zero",
                 static_cast<unsigned long long>(config_.control.command_timeout_ms));
    events_.changed(changes);
    arm_deadline();
    pilots_.tell_failsafes();
}

std::string Vehicle::start(sd_event* event) {
    std::string error = deadline_.start(event);
    arm_deadline();
    return error;
}

Result Vehicle::kill(KillSource source, std::string_view reason) {
    const bool was_killed = safety_.state() == SafetyState::Killed;
    const Result turn_ends{Status::Killed, "the vehicle was killed during the turn"};
    handle(safety_.kill(source, monotonic_ns(), reason), &turn_ends);
    if (!was_killed && safety_.state() == SafetyState::Killed)
        log_warning("KILLED by %s%s%s", std::string(condition_.kill_source_name()).c_str(), reason.empty() ? "" : ": ",
                    std::string(reason).c_str());
    return {};
}

Result Vehicle::clear_kill() {
    if (Result r = condition_.clear_kill_refusal(); !r.ok())
        return r;
    if (Result r = clear(); !r.ok())
        return r;
    log_notice("kill cleared; arming for %u ms", config_.control.arming_delay_ms);
    return {};
}

Result Vehicle::clear() {
    SafetyAction a = safety_.clear_kill(monotonic_ns());
    if (!a.ok())
        return {status_of(a.error), a.message};
    handle(a);
    return {};
}

Result Vehicle::power_off(std::string_view confirmation) {
    if (Result r = VehicleCondition::power_off_refusal(confirmation); !r.ok())
        return r;
    SafetyAction a = safety_.power_off(monotonic_ns());
    if (a.error == SafetyError::PoweredOff)
        return {Status::PoweredOff, a.message};
    const Result turn_ends{Status::PoweredOff, "the vehicle was powered off during the turn"};
    handle(a, &turn_ends);
    actuator_.power_off(); // thrusters first, whatever handle() decided; then the line
    log_warning("POWER-OFF confirmed: thrusters to zero%s", lines_.has_power_off() ? ", then the power-off line" : "");
    return {};
}

void Vehicle::kill_switch_read(bool set) {
    if (set == safety_.kill_switch_set())
        return;
    const bool was_killed = safety_.state() == SafetyState::Killed;
    const Result turn_ends{Status::Killed, "the kill switch was set during the turn"};
    handle(safety_.switch_changed(set, monotonic_ns()), set ? &turn_ends : nullptr);
    if (set && !was_killed)
        log_warning("KILLED by the kill switch");
    else if (!set)
        log_notice("kill switch released; ClearKill re-arms the vehicle");
}

} // namespace caracara
