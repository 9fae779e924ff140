// What a simulated device on an SPI port implements (the Teensy): the port owns timing and the
// wire log; a slave only decides what it shifts out.
#pragma once

#include <cstdint>
#include <span>

namespace caracara::sim {

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

} // namespace caracara::sim
