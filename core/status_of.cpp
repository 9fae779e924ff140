#include "core/status_of.hpp"

namespace caracara {

Status status_of(PacketError e) {
    switch (e) {
    case PacketError::None: return Status::Ok;
    case PacketError::WrongLength: return Status::InvalidLength;
    case PacketError::MotorOutOfRange:
    case PacketError::ColorOutOfRange: return Status::OutOfRange;
    case PacketError::BadPowerOffState: return Status::InvalidValue;
    }
    return Status::InvalidValue;
}

Status status_of(BudgetError e) {
    switch (e) {
    case BudgetError::None: return Status::Ok;
    case BudgetError::OutOfRange: return Status::OutOfRange;
    case BudgetError::OverBudget: return Status::OverBudget;
    }
    return Status::OutOfRange;
}

Status status_of(MixError e) {
    switch (e) {
    case MixError::None: return Status::Ok;
    case MixError::NotFinite: return Status::InvalidValue;
    default: return Status::OutOfRange;
    }
}

Status status_of(SafetyError e) {
    switch (e) {
    case SafetyError::None: return Status::Ok;
    case SafetyError::NotKilled: return Status::NotKilled;
    case SafetyError::KillSwitchSet: return Status::KillSwitchSet;
    case SafetyError::PoweredOff: return Status::PoweredOff;
    case SafetyError::NotReady: return Status::Arming;
    }
    return Status::Killed;
}

} // namespace caracara
