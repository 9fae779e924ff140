// Tells a locked I2C bus from one absent thruster: several bus-level errors in a row
// (timeouts, clock-stretch/EIO, lost arbitration, a vanished adapter), or every thruster
// failing at once. A bad reply still crossed the wire: it clears the count.
#pragma once

#include <cstdint>
#include <string>

namespace caracara {

class LockupDetector {
public:
    enum class Transfer {
        Ok,
        BadReply,    // arrived, but wrong first byte or checksum: the thruster's fault
        DeviceError, // NACK and the like: one device, not the wire
        BusError,    // the wire or the adapter
    };
    static constexpr uint32_t kBusErrors = 3;
    static constexpr uint32_t kFailuresPerThruster = 2;

    explicit LockupDetector(uint32_t thrusters) : failure_limit_(kFailuresPerThruster * thrusters) {}

    // True when this transfer makes it a lockup; reason() then says why.
    bool note(Transfer t);
    void reset();
    std::string reason(const std::string& last_error) const;

private:
    uint32_t failure_limit_;
    uint32_t bus_errors_ = 0;
    uint32_t failures_ = 0;
};

} // namespace caracara
