// A simulated spidev node (SimVehicle::spi_port): the slave behind it, the mode the master set,
// and counts for inspection and tests.
#pragma once

#include "sim/spi_slave.hpp"

#include <cstdint>

namespace caracara::sim {

struct SpiPort {
    SpiSlave* slave = nullptr;
    uint8_t mode = 0;
    uint8_t bits_per_word = 8;
    uint32_t max_speed_hz = 500000;
    uint8_t lsb_first = 0;
    uint64_t messages = 0;
    uint64_t mode_mismatches = 0;
    // The shape of the last SPI_IOC_MESSAGE, for tests of the spidev marshalling.
    uint32_t last_transfers = 0;
    uint32_t last_speed_hz = 0;
    uint16_t last_delay_usecs = 0;
    // A hung slave (caracara-sim's Teensy fault SetHang): every message is answered this late.
    uint32_t hang_ms = 0;
};

} // namespace caracara::sim
