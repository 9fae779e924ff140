// The outcome of every command, and the one table of the names D-Bus callers see as
// org.caracara.Vehicle1.Error.<name> (dbus/ adds the prefix; nothing else names errors).
#pragma once

#include <string>
#include <string_view>

namespace caracara {

// Outcome of a command, mapped 1:1 to org.caracara.Vehicle1.Error.<name> by dbus/.
enum class Status {
    Ok,
    InvalidLength,
    OutOfRange,
    InvalidValue,
    Killed,
    Arming,
    PoweredOff,
    OverBudget,
    NotKilled,
    KillSwitchSet,
    ConfirmationRequired,
    Busy,
    Timeout,
    LinkError,
    Hardware,
    UnknownProfile,
    BusLost,
    ThrusterUnreachable,
    Surfacing,       // a failsafe's ascent is running: other motion waits for it (Kill does not)
    FailsafeActive,  // ClearKill while the failsafe that killed still holds
    NotStill,        // direction detection: the vehicle did not settle before a pulse
};
std::string_view status_name(Status s); // "OutOfRange", ...

struct Result {
    Status status = Status::Ok;
    std::string message;
    bool ok() const { return status == Status::Ok; }
};

} // namespace caracara
