// What a simulated device on a bus implements. The bus models (I2C, SPI) own timing,
// the wire log and the line model; a slave only decides what it answers.
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
};

struct SpiTransferParams {
    uint32_t speed_hz = 0;
    uint16_t delay_usecs = 0;
    uint8_t bits_per_word = 8;
    bool cs_change = false;
};

class SpiSlave {
public:
    virtual ~SpiSlave() = default;
    // Full duplex: `rx` has the same length as `tx` and receives what the slave shifts out
    // while `tx` is shifted in. One call per spi_ioc_transfer; chip select stays asserted
    // between transfers of one SPI_IOC_MESSAGE unless cs_change is set.
    virtual void transfer(std::span<const uint8_t> tx, std::span<uint8_t> rx, const SpiTransferParams& p,
                          uint64_t now_ns) = 0;
    // Chip select released at the end of an SPI_IOC_MESSAGE.
    virtual void end_message(uint64_t now_ns) { (void)now_ns; }
};

// Physics step for models that evolve in time (thruster ramp and heat, vehicle attitude).
class Stepped {
public:
    virtual ~Stepped() = default;
    virtual void step(double dt_s, uint64_t now_ns) = 0;
};

} // namespace caracara::sim
