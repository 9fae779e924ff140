// One transfer of an SPI message (SPI_IOC_MESSAGE) as the simulated vehicle carries it
// (SimVehicle::spi_message): what the master sends, and the slave's answer.
#pragma once

#include "sim/spi_slave.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace caracara::sim {

struct SpiMessageXfer {
    std::vector<uint8_t> tx;  // empty when the transfer had no tx_buf (the master sends zeros)
    size_t len = 0;
    bool want_rx = false;
    SpiTransferParams params;
    std::vector<uint8_t> rx;  // filled by the vehicle
};

} // namespace caracara::sim
