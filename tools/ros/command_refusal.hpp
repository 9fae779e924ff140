// Why caracara-ros or caracarad refused a command from a ROS writer: the kinds counted on
// /diagnostics and named in the journal (core/enum_names.hpp names them).
#pragma once

#include "core/enum_names.hpp"

#include <string_view>

namespace caracara::ros {

enum class CommandRefusal {
    BadValue,  // a wrong count, out of range, not a number (InvalidLength, OutOfRange, InvalidValue)
    Killed,    // the vehicle takes no command: killed, arming, powered off
    NotHolder, // another writer holds the vehicle
    Other,     // any other error the daemon names (a failsafe, surfacing, the bus lost, ...)
};

// The refusal kind of one of the daemon's error names (org.caracara.Vehicle1.Error.X).
inline CommandRefusal refusal_of(std::string_view error_name) {
    const std::string_view n = error_name.substr(error_name.rfind('.') + 1);
    if (n == "InvalidLength" || n == "OutOfRange" || n == "InvalidValue")
        return CommandRefusal::BadValue;
    if (n == "Killed" || n == "Arming" || n == "PoweredOff")
        return CommandRefusal::Killed;
    return CommandRefusal::Other;
}

} // namespace caracara::ros

namespace caracara {

template <>
struct EnumNames<ros::CommandRefusal> {
    static constexpr std::array<EnumName<ros::CommandRefusal>, 4> table{{
        {ros::CommandRefusal::BadValue, "bad-value"},
        {ros::CommandRefusal::Killed, "killed"},
        {ros::CommandRefusal::NotHolder, "not-holder"},
        {ros::CommandRefusal::Other, "other"},
    }};
};

} // namespace caracara
