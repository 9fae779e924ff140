#include "core/safety.hpp"

#include "core/clock.hpp"

namespace caracara {

SafetyMachine::SafetyMachine(SafetyConfig config, bool kill_switch_set, uint64_t now)
    : config_(config), switch_set_(kill_switch_set), arming_started_(now) {
    if (kill_switch_set)
        enter_killed(KillSource::Switch, now, "kill switch set at start");
    else if (config_.start_killed)
        enter_killed(KillSource::Start, now, "started killed; ClearKill arms the vehicle");
}

void SafetyMachine::drop_commands() { commands_.drop(); }

void SafetyMachine::enter_killed(KillSource source, uint64_t now, std::string_view reason) {
    state_ = SafetyState::Killed;
    kill_.source = source;
    kill_.reason = reason.empty() ? std::string(kill_source_name(source)) : std::string(reason);
    kill_.at = now;
    drop_commands();
    pilots_.clear(); // nothing left to lose
}

SafetyAction SafetyMachine::kill(KillSource source, uint64_t now, std::string_view reason) {
    if (source == KillSource::None)
        source = KillSource::Bus;  // a kill without a named source is still a kill
    if (state_ == SafetyState::PoweredOff)
        return SafetyAction::zeroing("powered off", false);
    if (state_ == SafetyState::Killed && kill_.source != KillSource::Start)
        return SafetyAction::zeroing("already killed (" + std::string(kill_source_name(kill_.source)) + ")", false);
    // A start kill is the weakest source: any real kill names itself in its place (a switch
    // set at start reads "switch", and ClearKill then asks for it to be released).
    enter_killed(source, now, reason);
    return SafetyAction::zeroing("killed (" + std::string(kill_source_name(source)) + "): " + kill_.reason, true);
}

SafetyAction SafetyMachine::clear_kill(uint64_t now) {
    if (state_ == SafetyState::PoweredOff)
        return SafetyAction::refused(SafetyError::PoweredOff, "powered off: a kill cannot be cleared");
    if (state_ != SafetyState::Killed)
        return SafetyAction::refused(SafetyError::NotKilled, "not killed (" + std::string(state_name(state_)) + ")");
    if (switch_set_)
        return SafetyAction::refused(SafetyError::KillSwitchSet, "the kill switch is set: release it first");
    state_ = SafetyState::Arming;
    kill_.source = KillSource::None;
    kill_.reason.clear();
    arming_started_ = now;
    drop_commands();
    pilots_.clear(); // armed again: pilots are those who command from now on
    return SafetyAction::zeroing("kill cleared, arming", true);
}

SafetyAction SafetyMachine::switch_changed(bool set, uint64_t now) {
    switch_set_ = set;
    if (set)
        return kill(KillSource::Switch, now, "kill switch set");
    SafetyAction a;
    a.message = "kill switch released";
    return a;
}

SafetyAction SafetyMachine::power_off(uint64_t now) {
    if (state_ == SafetyState::PoweredOff)
        return SafetyAction::refused(SafetyError::PoweredOff, "already powered off");
    (void)now;
    state_ = SafetyState::PoweredOff;
    drop_commands();
    pilots_.clear();
    return SafetyAction::zeroing("powering off", true);
}

SafetyAction SafetyMachine::tick(uint64_t now) {
    SafetyAction a;
    if (state_ == SafetyState::Arming && elapsed(arming_started_, now) >= config_.arming_delay_ns) {
        state_ = SafetyState::Ready;
        drop_commands();
        a.state_changed = true;
        a.message = "armed, ready";
        return a;
    }
    if (state_ == SafetyState::Ready && commands_.active() &&
        elapsed(commands_.last_command_at(), now) >= config_.command_timeout_ns) {
        a = SafetyAction::zeroing("no command for " + std::to_string(elapsed(commands_.last_command_at(), now) / 1'000'000) +
                                      " ms (timeout " + std::to_string(config_.command_timeout_ns / 1'000'000) + " ms)",
                                  false);
        a.command_stale = true;
        drop_commands();
    }
    return a;
}

SafetyAction SafetyMachine::accept_command(uint64_t now, std::string_view client) {
    switch (state_) {
    case SafetyState::PoweredOff:
        return SafetyAction::refused(SafetyError::PoweredOff, "powered off");
    case SafetyState::Killed:
        return SafetyAction::refused(SafetyError::NotReady, "killed (" +
                                                                std::string(kill_source_name(kill_.source)) +
                                                                "): clear the kill first");
    case SafetyState::Arming:
        return SafetyAction::refused(SafetyError::NotReady,
                                     "arming: ready in " + std::to_string(arming_remaining_ns(now) / 1'000'000) + " ms");
    case SafetyState::Ready:
        break;
    }
    commands_.accepted(client, now);
    pilots_.commanded(client);
    return {};
}

SafetyAction SafetyMachine::client_left(std::string_view client, uint64_t now) {
    (void)now;
    pilots_.left(client);
    if (!commands_.active() || client != commands_.client())
        return {};
    drop_commands();
    return SafetyAction::zeroing("commanding client " + std::string(client) + " left", false);
}

uint64_t SafetyMachine::arming_remaining_ns(uint64_t now) const {
    if (state_ != SafetyState::Arming)
        return 0;
    const uint64_t e = elapsed(arming_started_, now);
    return e >= config_.arming_delay_ns ? 0 : config_.arming_delay_ns - e;
}

uint64_t SafetyMachine::next_deadline() const {
    if (state_ == SafetyState::Arming)
        return arming_started_ + config_.arming_delay_ns;
    if (state_ == SafetyState::Ready && commands_.active())
        return commands_.last_command_at() + config_.command_timeout_ns;
    return kNoDeadline;
}

} // namespace caracara
