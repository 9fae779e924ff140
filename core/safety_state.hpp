// The safety state machine's words (core/safety): its states, what killed the vehicle, why it
// refused an event; each with the name logs, D-Bus and tests use.
#pragma once

#include "core/enum_names.hpp"

#include <string_view>

namespace caracara {

enum class SafetyState { Arming, Ready, Killed, PoweredOff };
template <>
struct EnumNames<SafetyState> {
    static constexpr std::array<EnumName<SafetyState>, 4> table{{
        {SafetyState::Arming, "arming"},
        {SafetyState::Ready, "ready"},
        {SafetyState::Killed, "killed"},
        {SafetyState::PoweredOff, "powered-off"},
    }};
};
inline std::string_view state_name(SafetyState v) { return name_of(v); }

enum class KillSource {
    None,    // not killed
    DBus,    // the Kill method
    Switch,  // the kill switch GPIO
    Packet,  // a legacy packet with killState != 0
    Bus,     // the I2C bus lost: it could not be recovered, or a lockup outlasted the command timeout
    Start,   // every start of the daemon, until someone decides to arm it (ClearKill)
    Device,  // a line or device the daemon drives went away (kill/power-off output, the Teensy's SPI)
    Failsafe, // a failsafe's kill, or the end of its ascent (core/failsafe_policy)
};
// "none", "dbus", "switch", "packet", "bus", "start", "device", "failsafe"
template <>
struct EnumNames<KillSource> {
    static constexpr std::array<EnumName<KillSource>, 8> table{{
        {KillSource::None, "none"},
        {KillSource::DBus, "dbus"},
        {KillSource::Switch, "switch"},
        {KillSource::Packet, "packet"},
        {KillSource::Bus, "bus"},
        {KillSource::Start, "start"},
        {KillSource::Device, "device"},
        {KillSource::Failsafe, "failsafe"},
    }};
};
inline std::string_view kill_source_name(KillSource v) { return name_of(v); }

enum class SafetyError {
    None,
    NotKilled,      // clear_kill while not killed
    KillSwitchSet,  // clear_kill while the kill switch is still set
    PoweredOff,     // anything that needs power after power-off
    NotReady,       // a thrust command while arming or killed
};
template <>
struct EnumNames<SafetyError> {
    static constexpr std::array<EnumName<SafetyError>, 5> table{{
        {SafetyError::None, "None"},
        {SafetyError::NotKilled, "NotKilled"},
        {SafetyError::KillSwitchSet, "KillSwitchSet"},
        {SafetyError::PoweredOff, "PoweredOff"},
        {SafetyError::NotReady, "NotReady"},
    }};
};
inline std::string_view error_name(SafetyError v) { return name_of(v); }

} // namespace caracara
