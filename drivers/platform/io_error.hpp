// Typed device errors: what a transfer failure means on this hardware, mapped from errno
// the way the Linux i2c/spi bus drivers report it (i2c-bcm2835, i2c-designware: EREMOTEIO a
// NACK, ETIMEDOUT a timeout, EIO a clock-stretch timeout, EAGAIN lost arbitration).
#pragma once

#include "core/enum_names.hpp"
#include "core/lockup_detector.hpp"

#include <string>
#include <string_view>

namespace caracara {

enum class IoError {
    None = 0,
    Nack,          // EREMOTEIO / ENXIO: no ACK from the slave (absent, busy, or unpowered)
    Timeout,       // ETIMEDOUT: the controller gave up on the transfer
    ClockStretch,  // EIO: clock-stretch timeout or bus error (a stuck line looks like this)
    Arbitration,   // EAGAIN: arbitration lost
    NoDevice,      // ENOENT / ENODEV: the device node or adapter is gone (driver unbound)
    BadReply,      // the reply arrived but its first byte or checksum was wrong
    Unsupported,   // the adapter lacks a required functionality (I2C_FUNCS) or ioctl
    Other,
};

IoError io_error_from_errno(int err);   // err is positive errno
template <>
struct EnumNames<IoError> {
    static constexpr std::array<EnumName<IoError>, 9> table{{
        {IoError::None, "none"},
        {IoError::Nack, "nack"},
        {IoError::Timeout, "timeout"},
        {IoError::ClockStretch, "clock-stretch"},
        {IoError::Arbitration, "arbitration-lost"},
        {IoError::NoDevice, "no-device"},
        {IoError::BadReply, "bad-reply"},
        {IoError::Unsupported, "unsupported"},
        {IoError::Other, "other"},
    }};
};
inline std::string_view io_error_name(IoError v) { return name_of(v); }
std::string errno_name(int err);       // "ETIMEDOUT (Connection timed out)"
// What a transfer's outcome says about the wire, for lockup detection: timeouts, EIO, lost
// arbitration and a vanished adapter are the bus's; a NACK is one device's.
LockupDetector::Transfer lockup_transfer(IoError e);

} // namespace caracara
