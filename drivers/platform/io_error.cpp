#include "drivers/platform/io_error.hpp"

#include <cerrno>
#include <cstring>

namespace caracara {

IoError io_error_from_errno(int err) {
    switch (err) {
    case 0: return IoError::None;
    case EREMOTEIO:
    case ENXIO: return IoError::Nack;
    case ETIMEDOUT: return IoError::Timeout;
    case EIO: return IoError::ClockStretch;
    case EAGAIN: return IoError::Arbitration;
    case ENOENT:
    case ENODEV: return IoError::NoDevice;
    case EOPNOTSUPP:
    case ENOTTY: return IoError::Unsupported;
    default: return IoError::Other;
    }
}

std::string errno_name(int err) {
    const char* name = strerrorname_np(err);
    std::string s = name ? name : ("errno " + std::to_string(err));
    s += " (";
    s += std::strerror(err);
    s += ")";
    return s;
}

LockupDetector::Transfer lockup_transfer(IoError e) {
    switch (e) {
    case IoError::None: return LockupDetector::Transfer::Ok;
    case IoError::BadReply: return LockupDetector::Transfer::BadReply;
    case IoError::Timeout:
    case IoError::ClockStretch:
    case IoError::Arbitration:
    case IoError::NoDevice: return LockupDetector::Transfer::BusError;
    case IoError::Nack:
    case IoError::Unsupported:
    case IoError::Other: return LockupDetector::Transfer::DeviceError;
    }
    return LockupDetector::Transfer::DeviceError;
}

} // namespace caracara
