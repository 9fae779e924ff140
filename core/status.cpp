#include "core/status.hpp"

namespace caracara {

std::string_view status_name(Status s) {
    switch (s) {
    case Status::Ok: return "Ok";
    case Status::InvalidLength: return "InvalidLength";
    case Status::OutOfRange: return "OutOfRange";
    case Status::InvalidValue: return "InvalidValue";
    case Status::Killed: return "Killed";
    case Status::Arming: return "Arming";
    case Status::PoweredOff: return "PoweredOff";
    case Status::OverBudget: return "OverBudget";
    case Status::NotKilled: return "NotKilled";
    case Status::KillSwitchSet: return "KillSwitchSet";
    case Status::ConfirmationRequired: return "ConfirmationRequired";
    case Status::Busy: return "Busy";
    case Status::Timeout: return "Timeout";
    case Status::LinkError: return "LinkError";
    case Status::Hardware: return "Hardware";
    case Status::UnknownProfile: return "UnknownProfile";
    case Status::BusLost: return "BusLost";
    case Status::ThrusterUnreachable: return "ThrusterUnreachable";
    case Status::Surfacing: return "Surfacing";
    case Status::FailsafeActive: return "FailsafeActive";
    case Status::NotStill: return "NotStill";
    }
    return "Hardware";
}

} // namespace caracara
