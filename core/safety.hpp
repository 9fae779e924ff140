// The safety state machine and the command watchdog (docs/architecture.md, "A kill switch edge to the wire"; README "Safety").
// Pure logic: the owner feeds it events with the monotonic time in nanoseconds and acts on
// the returned SafetyAction (zero the thrusters now, drop stored commands); it never
// touches hardware itself, so every rule here is unit-tested.
//
//   start ──> Arming ──(arming delay, zero output)──> Ready
//   start with the kill switch set ──> Killed (switch); start_killed ──> Killed (start)
//   Arming/Ready ──kill (dbus, switch, packet, fault)──> Killed   (latches)
//   Killed ──clear_kill, switch released──> Arming
//   any ──power_off──> PoweredOff   (irreversible)
//
// A silent command stream (timeout) or a commanding client that left zeroes the output
// and drops the stored commands, but is NOT a kill: the next command drives again. Who
// commanded since the vehicle was armed is its PilotRoster: when the last pilot has left,
// pilot_lost() holds, and the failsafes kill after its persistence (core/failsafe_policy).
// An escalated fault (e.g. a failed I2C bus recovery) is a kill with source Fault.
#pragma once

#include "core/command_stream.hpp"
#include "core/kill_record.hpp"
#include "core/pilot_roster.hpp"
#include "core/safety_action.hpp"
#include "core/safety_config.hpp"
#include "core/safety_state.hpp"

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

namespace caracara {

class SafetyMachine {
public:
    static constexpr uint64_t kNoDeadline = std::numeric_limits<uint64_t>::max();

    // Starts in Arming; Killed (source Switch) when the kill switch is already set, else
    // Killed (source Start) when config.start_killed.
    SafetyMachine(SafetyConfig config, bool kill_switch_set, uint64_t now);

    // Always accepted: from Arming/Ready it latches Killed with this source; when already
    // killed the first source is kept, except Start, which any other source replaces; after power-off it only repeats the zeroing.
    // KillSource::None is recorded as Fault: a kill is never ignored for a missing source.
    SafetyAction kill(KillSource source, uint64_t now, std::string_view reason = {});
    // Killed -> Arming. Refused with NotKilled, KillSwitchSet or PoweredOff.
    SafetyAction clear_kill(uint64_t now);
    // set -> kill (source Switch); released -> recorded only: clearing stays explicit.
    SafetyAction switch_changed(bool set, uint64_t now);
    // Irreversible. Refused with PoweredOff when already powered off.
    SafetyAction power_off(uint64_t now);
    // Ends the arming delay and runs the command watchdog; call at least at next_deadline().
    SafetyAction tick(uint64_t now);
    // A thrust/motion command from `client` (its unique name on the bus). Accepted only in
    // Ready (NotReady while arming or killed, PoweredOff after power-off); it (re)starts
    // the watchdog and makes `client` the commanding client.
    SafetyAction accept_command(uint64_t now, std::string_view client = {});
    // A client left the bus: if it was the commanding client, zero and drop its commands; if it
    // was a pilot, the roster knows (pilot_lost).
    SafetyAction client_left(std::string_view client, uint64_t now);
    // Armed (arming or ready), a pilot left since, and no pilot remains on the bus: the
    // pilot-lost failsafe's condition. The failsafe's own ascent counts as a pilot, so a pilot
    // who leaves during it does not cut it short (it ends in a kill anyway).
    bool pilot_lost() const {
        return (state_ == SafetyState::Arming || state_ == SafetyState::Ready) && pilots_.lost();
    }
    const PilotRoster& pilots() const { return pilots_; }

    SafetyState state() const { return state_; }
    // The latched kill: source, reason, time.
    const KillRecord& kill_record() const { return kill_; }
    bool kill_switch_set() const { return switch_set_; }
    // Commands may drive the thrusters (state Ready); otherwise the output is zero.
    bool may_drive() const { return state_ == SafetyState::Ready; }
    // Ready and a command stream is live (not stale, client present).
    bool command_active() const { return may_drive() && commands_.active(); }
    // The kill output de-energizes the thrusters while killed or powered off. It is
    // released on entering Arming so the controllers power up and settle at zero order.
    bool kill_output_asserted() const {
        return state_ == SafetyState::Killed || state_ == SafetyState::PoweredOff;
    }
    // The command stream: its commanding client and its last command's time.
    const CommandStream& commands() const { return commands_; }
    uint64_t arming_remaining_ns(uint64_t now) const;
    // The next time tick() has work (end of arming, watchdog expiry), or kNoDeadline.
    uint64_t next_deadline() const;
    const SafetyConfig& config() const { return config_; }

private:
    void enter_killed(KillSource source, uint64_t now, std::string_view reason);
    void drop_commands();

    SafetyConfig config_;
    SafetyState state_ = SafetyState::Arming;
    KillRecord kill_;
    bool switch_set_ = false;
    uint64_t arming_started_ = 0;
    CommandStream commands_;
    PilotRoster pilots_; // since the vehicle was last armed
};

} // namespace caracara
