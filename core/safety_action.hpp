// What the safety state machine (core/safety) returns for each event.
#pragma once

#include "core/safety_state.hpp"

#include <string>
#include <utility>

namespace caracara {

// What the owner must do after an event. The flags are idempotent: acting on them twice
// is harmless, missing one is not.
struct SafetyAction {
    SafetyError error = SafetyError::None;
    std::string message;          // the reason, for logs and the caller
    bool state_changed = false;
    bool zero_outputs = false;    // order zero to every thruster now, not at the next tick
    bool clear_commands = false;  // drop stored commands so nothing resumes by itself
    bool command_stale = false;   // the watchdog expired on this call (not a kill)
    bool ok() const { return error == SafetyError::None; }

    static SafetyAction refused(SafetyError e, std::string message) {
        SafetyAction a;
        a.error = e;
        a.message = std::move(message);
        return a;
    }
    // Zero now and drop the stored commands: a kill, a power-off, a ClearKill, a silent stream.
    static SafetyAction zeroing(std::string message, bool state_changed) {
        SafetyAction a;
        a.message = std::move(message);
        a.state_changed = state_changed;
        a.zero_outputs = true;
        a.clear_commands = true;
        return a;
    }
};

} // namespace caracara
