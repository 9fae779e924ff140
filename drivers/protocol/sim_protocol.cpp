#include "drivers/protocol/sim_protocol.hpp"

#include <linux/i2c-dev.h>
#include <linux/spi/spidev.h>
#include <sys/ioctl.h>

namespace caracara::simproto {

IoctlArg classify_ioctl(unsigned long request) {
    switch (request) {
    case I2C_SLAVE:
    case I2C_SLAVE_FORCE:
    case I2C_TENBIT:
    case I2C_PEC:
    case I2C_TIMEOUT:
    case I2C_RETRIES:
        return {ArgKind::Value, 0};
    case I2C_FUNCS:
        return {ArgKind::PtrOut, sizeof(unsigned long)};
    case SPI_IOC_RD_MODE:
    case SPI_IOC_RD_LSB_FIRST:
    case SPI_IOC_RD_BITS_PER_WORD:
    case SPI_IOC_RD_MAX_SPEED_HZ:
    case SPI_IOC_RD_MODE32:
        return {ArgKind::PtrOut, _IOC_SIZE(request)};
    case SPI_IOC_WR_MODE:
    case SPI_IOC_WR_LSB_FIRST:
    case SPI_IOC_WR_BITS_PER_WORD:
    case SPI_IOC_WR_MAX_SPEED_HZ:
    case SPI_IOC_WR_MODE32:
        return {ArgKind::PtrIn, _IOC_SIZE(request)};
    default:
        return {ArgKind::Unknown, 0};
    }
}

} // namespace caracara::simproto
