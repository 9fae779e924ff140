// What a simulated device on the I2C bus implements: the bus model owns timing, the wire log
// and the line model; a slave only decides what it answers.
#pragma once

#include <cstdint>
#include <span>

namespace caracara::sim {

class I2cSlave {
public:
    virtual ~I2cSlave() = default;
    // Address phase: false means the slave does not ACK its address (the master sees a NACK).
    virtual bool ack_address(bool read) = 0;
    // A complete write message (after the address byte) that was ACKed.
    virtual void on_write(std::span<const uint8_t> data, uint64_t now_ns) = 0;
    // Fill a read message (after the address byte); the master ACKs every byte but the last.
    virtual void on_read(std::span<uint8_t> out, uint64_t now_ns) = 0;
    // How long the slave holds SCL low (clock stretching) in each message addressed to it; a
    // hung device holds it longer than the adapter waits, and the transfer times out.
    virtual uint64_t stretch_ns() const { return 0; }
};

} // namespace caracara::sim
