// spidev access through the device seam: the same SPI_IOC_WR_* setup and SPI_IOC_MESSAGE
// spi_ioc_transfer arrays the SBC's kernel receives, whether the seam leads to the kernel or
// to caracara-sim.
#pragma once

#include "core/link_config.hpp"
#include "drivers/platform/device_io.hpp"

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <utility>

namespace caracara {

class SpiDev {
public:
    // Per-byte mode builds its transfer array on the stack; Teensy frames are at most 10
    // bytes, so that is the cap (longer buffers are rejected with -EMSGSIZE).
    static constexpr size_t kMaxPerByteTransfers = 10;
    // spidev's default bufsiz: the kernel rejects longer messages with -EMSGSIZE anyway.
    static constexpr size_t kMaxTransfer = 4096;

    SpiDev(DeviceIo& io, std::string path, SpiConfig config = {})
        : io_(io), path_(std::move(path)), config_(config) {}
    ~SpiDev() { close(); }
    SpiDev(const SpiDev&) = delete;
    SpiDev& operator=(const SpiDev&) = delete;

    // Opens the node and sets mode 0, 8 bits per word and the configured speed.
    // Returns 0 or -errno (-EINVAL for a zero speed); on failure the node is closed again.
    int open();
    void close();
    bool is_open() const { return fd_ >= 0; }
    const std::string& path() const { return path_; }
    const SpiConfig& config() const { return config_; }

    // One full-duplex SPI_IOC_MESSAGE under a single chip select: tx is shifted out while
    // rx fills. tx and rx must have the same non-zero length. Returns 0 or -errno
    // (-ENODEV when not open, -EINVAL on bad spans, -EMSGSIZE when too long, -EIO when the
    // kernel reports fewer bytes than requested). No heap allocation.
    int transfer(std::span<const uint8_t> tx, std::span<uint8_t> rx);
    int last_errno() const { return last_errno_; }

private:
    int fail(int neg_errno);

    DeviceIo& io_;
    std::string path_;
    SpiConfig config_;
    int fd_ = -1;
    int last_errno_ = 0;
};

} // namespace caracara
