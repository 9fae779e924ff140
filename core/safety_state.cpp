#include "core/safety_state.hpp"

namespace caracara {

std::string_view state_name(SafetyState s) {
    switch (s) {
    case SafetyState::Arming: return "arming";
    case SafetyState::Ready: return "ready";
    case SafetyState::Killed: return "killed";
    case SafetyState::PoweredOff: return "powered-off";
    }
    return "?";
}

std::string_view kill_source_name(KillSource s) {
    switch (s) {
    case KillSource::None: return "none";
    case KillSource::DBus: return "dbus";
    case KillSource::Switch: return "switch";
    case KillSource::Packet: return "packet";
    case KillSource::Fault: return "bus"; // the escalated fault is the I2C bus that could not be recovered
    case KillSource::Start: return "start";
    case KillSource::Device: return "device";
    case KillSource::Failsafe: return "failsafe";
    }
    return "?";
}

std::string_view error_name(SafetyError e) {
    switch (e) {
    case SafetyError::None: return "None";
    case SafetyError::NotKilled: return "NotKilled";
    case SafetyError::KillSwitchSet: return "KillSwitchSet";
    case SafetyError::PoweredOff: return "PoweredOff";
    case SafetyError::NotReady: return "NotReady";
    }
    return "?";
}

} // namespace caracara
