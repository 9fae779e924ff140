#include "daemon/vehicle.hpp"

#include "core/clock.hpp"
#include "core/packet.hpp"
#include "core/status_of.hpp"

#include "daemon/log.hpp"

namespace caracara {

namespace {
constexpr const char* kPowerOffConfirmation = "power-off";
static_assert(DeadlineTimer::kNever == SafetyMachine::kNoDeadline);
} // namespace

Vehicle::Vehicle(const DaemonConfig& config, ThrusterBus& bus, SafetyLines& lines, TeensyPort& teensy,
                 VehicleEvents& events)
    : config_(config),
      bus_(bus),
      lines_(lines),
      teensy_(teensy),
      events_(events),
      actuator_(bus, lines, teensy),
      safety_(safety_config(config), false, monotonic_ns()),
      deadline_([this] { tick(monotonic_ns()); }),
      motors_(config, safety_, *this, deadline_, actuator_, events),
      condition_(safety_, bus, lines) {}

void Vehicle::handle(const SafetyAction& a) {
    uint32_t changes = 0;
    if (a.clear_commands) {
        motors_.clear();
        changes |= kChangeMotors | kChangeController;
    }
    if (safety_.kill_output_asserted())
        motors_.end_surfacing(); // a kill ends an ascent at once
    actuator_.carry_out(a, safety_.kill_output_asserted());
    if (a.state_changed)
        changes |= kChangeState;
    if (a.command_stale)
        log_info("command stream silent for %llu ms: thrusters to zero",
                 static_cast<unsigned long long>(config_.control.command_timeout_ms));
    events_.changed(changes);
    arm_deadline();
}

std::string Vehicle::start(sd_event* event) {
    std::string error = deadline_.start(event);
    arm_deadline();
    return error;
}

Result Vehicle::accept_command(std::string_view client) {
    if (motors_.surfacing())
        return {Status::Surfacing, "a failsafe is surfacing the vehicle; Kill stops it"};
    if (Result r = state_error(); !r.ok())
        return r;
    const std::string previous = safety_.commanding_client();
    if (!safety_.accept_command(monotonic_ns(), client).ok())
        return state_error();
    arm_deadline();
    if (previous != safety_.commanding_client())
        events_.changed(kChangeController);
    return {};
}

Result Vehicle::apply_packet(std::span<const int32_t> words, std::string_view client) {
    PacketResult pr = decode_packet(words);
    // The packet's author asked for a kill: it happens even when another field is refused,
    // and the call still returns that field's error with nothing else changed.
    if (pr.kill_requested && !powered_off())
        kill(KillSource::Packet, "packet killState=" + std::to_string(words[kPacketKill]));
    if (!pr.ok())
        return {status_of(pr.error), pr.message};
    if (powered_off())
        return state_error();
    const Packet& p = pr.packet;
    if (p.kill) {
        // The seed: a non-zero killState stops the motors until a zero is sent. Kill first,
        // then a power-off the same packet asks for.
        if (p.power_off)
            return power_off(kPowerOffConfirmation);
        set_leds(p.red, p.green, p.blue);
        return {};
    }
    if (p.power_off)
        return power_off(kPowerOffConfirmation);
    if (safety_.state() == SafetyState::Killed) {
        if (safety_.kill_source() != KillSource::Packet)
            return state_error();
        // killState 0 is the packet's "all clear": it clears a packet kill (arming follows).
        SafetyAction a = safety_.clear_kill(monotonic_ns());
        if (!a.ok())
            return {status_of(a.error), a.message};
        handle(a);
        set_leds(p.red, p.green, p.blue);
        return {};
    }
    Result r = motors_.accept(p.motors, false, client);
    if (!r.ok())
        return r;
    if (teensy_.leds() != std::array<uint8_t, 3>{p.red, p.green, p.blue})
        set_leds(p.red, p.green, p.blue);
    return {};
}

Result Vehicle::kill(KillSource source, std::string_view reason) {
    const bool was_killed = safety_.state() == SafetyState::Killed;
    handle(safety_.kill(source, monotonic_ns(), reason));
    if (!was_killed && safety_.state() == SafetyState::Killed)
        log_warning("KILLED by %s%s%s", std::string(kill_source_name()).c_str(), reason.empty() ? "" : ": ",
                    std::string(reason).c_str());
    actuator_.stop_wheels();
    actuator_.cancel_turn({Status::Killed, "the vehicle was killed during the turn"});
    return {};
}

void Vehicle::kill(KillSource source, std::string_view reason, Completion done) {
    actuator_.after_zeros(std::move(done), kill(source, reason));
}

void Vehicle::power_off(std::string_view confirmation, Completion done) {
    actuator_.after_zeros(std::move(done), power_off(confirmation));
}

void Vehicle::apply_packet(std::span<const int32_t> words, std::string_view client, Completion done) {
    const SafetyState before = safety_.state();
    Result r = apply_packet(words, client);
    const SafetyState after = safety_.state();
    // An error too: a refused packet that carried a kill still killed, and its zeros go first.
    if (after != before && (after == SafetyState::Killed || after == SafetyState::PoweredOff))
        actuator_.after_zeros(std::move(done), std::move(r));
    else
        done(r);
}

Result Vehicle::clear_kill() {
    if (Result r = condition_.clear_kill_refusal(); !r.ok())
        return r;
    SafetyAction a = safety_.clear_kill(monotonic_ns());
    if (!a.ok())
        return {status_of(a.error), a.message};
    handle(a);
    log_notice("kill cleared; arming for %u ms", config_.control.arming_delay_ms);
    return {};
}

Result Vehicle::power_off(std::string_view confirmation) {
    if (confirmation != kPowerOffConfirmation)
        return {Status::ConfirmationRequired,
                std::string("power-off is irreversible: pass the confirmation string \"") + kPowerOffConfirmation + "\""};
    SafetyAction a = safety_.power_off(monotonic_ns());
    if (a.error == SafetyError::PoweredOff)
        return {Status::PoweredOff, a.message};
    handle(a);
    actuator_.power_off(); // thrusters first, whatever handle() decided; then the line
    log_warning("POWER-OFF confirmed: thrusters to zero%s", lines_.has_power_off() ? ", then the power-off line" : "");
    actuator_.stop_wheels();
    actuator_.cancel_turn({Status::PoweredOff, "the vehicle was powered off during the turn"});
    return {};
}

Result Vehicle::set_leds(int red, int green, int blue, Completion done) {
    if (powered_off())
        return state_error();
    return teensy_.set_leds(red, green, blue, std::move(done));
}

void Vehicle::client_left(std::string_view unique_name) {
    if (unique_name.empty())
        return;
    const bool was_lost = safety_.pilot_lost();
    if (unique_name == safety_.commanding_client()) {
        log_notice("controlling client %s left the bus: thrusters to zero", std::string(unique_name).c_str());
        // Its zeros go behind what it had sent (ZeroOrder::Behind).
        handle(safety_.client_left(unique_name, monotonic_ns())); // announces Controller with the motors
    } else {
        safety_.client_left(unique_name, monotonic_ns()); // a pilot who no longer commands: no zeros
    }
    if (safety_.pilot_lost() && !was_lost) {
        log_warning("the last pilot (%s) left the bus: killed in %u ms (failsafe pilot-lost) unless a pilot commands",
                    std::string(unique_name).c_str(),
                    config_.failsafe.rule(FailsafeCondition::PilotLost).persistence_ms);
        if (failsafes_)
            failsafes_->conditions_changed();
    }
}

void Vehicle::link_changed() {
    // The kill is the failsafes' (teensy-link-lost, at once); a Vehicle without them (none in
    // the daemon: the FailsafeMonitor is its gate from its construction) still kills.
    if (failsafes_)
        failsafes_->conditions_changed();
    else if (teensy_.link_lost())
        kill(KillSource::Device, "the Teensy's SPI device went away");
}

void Vehicle::kill_switch_read(bool set) {
    if (set == safety_.kill_switch_set())
        return;
    const bool was_killed = safety_.state() == SafetyState::Killed;
    handle(safety_.switch_changed(set, monotonic_ns()));
    if (set && !was_killed)
        log_warning("KILLED by the kill switch");
    else if (!set)
        log_notice("kill switch released; ClearKill re-arms the vehicle");
    if (set && !was_killed)
        actuator_.stop_wheels();
    if (set)
        actuator_.cancel_turn({Status::Killed, "the kill switch was set during the turn"});
}

} // namespace caracara
