// The outcome of every command, and the one table of the names D-Bus callers see as
// org.caracara.Vehicle1.Error.<name> (dbus/ adds the prefix; nothing else names errors).
#pragma once

#include "core/enum_names.hpp"

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
template <>
struct EnumNames<Status> {
    static constexpr std::array<EnumName<Status>, 21> table{{
        {Status::Ok, "Ok"},
        {Status::InvalidLength, "InvalidLength"},
        {Status::OutOfRange, "OutOfRange"},
        {Status::InvalidValue, "InvalidValue"},
        {Status::Killed, "Killed"},
        {Status::Arming, "Arming"},
        {Status::PoweredOff, "PoweredOff"},
        {Status::OverBudget, "OverBudget"},
        {Status::NotKilled, "NotKilled"},
        {Status::KillSwitchSet, "KillSwitchSet"},
        {Status::ConfirmationRequired, "ConfirmationRequired"},
        {Status::Busy, "Busy"},
        {Status::Timeout, "Timeout"},
        {Status::LinkError, "LinkError"},
        {Status::Hardware, "Hardware"},
        {Status::UnknownProfile, "UnknownProfile"},
        {Status::BusLost, "BusLost"},
        {Status::ThrusterUnreachable, "ThrusterUnreachable"},
        {Status::Surfacing, "Surfacing"},
        {Status::FailsafeActive, "FailsafeActive"},
        {Status::NotStill, "NotStill"},
    }};
};
inline std::string_view status_name(Status v) { return name_of(v); }

struct Result {
    Status status = Status::Ok;
    std::string message;
    bool ok() const { return status == Status::Ok; }
};

} // namespace caracara
