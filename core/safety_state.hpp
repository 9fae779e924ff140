// The safety state machine's words (core/safety): its states, what killed the vehicle, why it
// refused an event; each with the name logs, D-Bus and tests use.
#pragma once

#include <string_view>

namespace caracara {

enum class SafetyState { Arming, Ready, Killed, PoweredOff };
std::string_view state_name(SafetyState s);  // "arming", "ready", "killed", "powered-off"

enum class KillSource {
    None,    // not killed
    DBus,    // the Kill method
    Switch,  // the kill switch GPIO
    Packet,  // a legacy packet with killState != 0
    Fault,   // an escalated fault, e.g. the I2C bus could not be recovered
    Start,   // every start of the daemon, until someone decides to arm it (ClearKill)
    Device,  // a line or device the daemon drives went away (kill/power-off output, the Teensy's SPI)
    Failsafe, // a failsafe's kill, or the end of its ascent (core/failsafe_policy)
};
// "none", "dbus", "switch", "packet", "bus", "start", "device", "failsafe"
std::string_view kill_source_name(KillSource s);

enum class SafetyError {
    None,
    NotKilled,      // clear_kill while not killed
    KillSwitchSet,  // clear_kill while the kill switch is still set
    PoweredOff,     // anything that needs power after power-off
    NotReady,       // a thrust command while arming or killed
};
std::string_view error_name(SafetyError e);  // "NotKilled", "KillSwitchSet", ... (for logs and tests)

} // namespace caracara
