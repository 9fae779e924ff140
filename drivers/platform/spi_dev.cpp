#include "drivers/platform/spi_dev.hpp"

#include <array>
#include <cerrno>
#include <fcntl.h>
#include <linux/spi/spi.h>
#include <linux/spi/spidev.h>
#include <sys/ioctl.h>

namespace caracara {

namespace {

// SPI_IOC_MESSAGE(N) sizes a char array by N, which must be a constant; per-byte mode picks
// N at run time, so build the same request number from its parts.
constexpr unsigned long spi_message_request(size_t n) {
    return _IOC(_IOC_WRITE, SPI_IOC_MAGIC, 0, n * sizeof(spi_ioc_transfer));
}
static_assert(spi_message_request(1) == SPI_IOC_MESSAGE(1));
static_assert(spi_message_request(SpiDev::kMaxPerByteTransfers) ==
              SPI_IOC_MESSAGE(SpiDev::kMaxPerByteTransfers));

__u64 user_ptr(const void* p) { return static_cast<__u64>(reinterpret_cast<uintptr_t>(p)); }

} // namespace

int SpiDev::open() {
    close();
    if (config_.speed_hz == 0)
        return -EINVAL;
    int fd = io_.open(path_.c_str(), O_RDWR);
    if (fd < 0)
        return fd;
    uint8_t mode = SPI_MODE_0;
    uint8_t bits = 8;
    uint32_t speed = config_.speed_hz;
    int r = io_.ioctl(fd, SPI_IOC_WR_MODE, &mode);
    if (r >= 0)
        r = io_.ioctl(fd, SPI_IOC_WR_BITS_PER_WORD, &bits);
    if (r >= 0)
        r = io_.ioctl(fd, SPI_IOC_WR_MAX_SPEED_HZ, &speed);
    if (r < 0) {
        io_.close(fd);
        return r;
    }
    fd_ = fd;
    return 0;
}

void SpiDev::close() {
    if (fd_ >= 0) {
        io_.close(fd_);
        fd_ = -1;
    }
}

int SpiDev::fail(int neg_errno) {
    // spidev answers ESHUTDOWN on a descriptor whose device was removed (its controller's driver
    // unbound): gone, as ENODEV says, so the node is closed and opened anew when it is back.
    if (neg_errno == -ESHUTDOWN)
        neg_errno = -ENODEV;
    last_errno_ = -neg_errno;
    return neg_errno;
}

int SpiDev::transfer(std::span<const uint8_t> tx, std::span<uint8_t> rx) {
    if (fd_ < 0)
        return fail(-ENODEV);
    if (tx.size() != rx.size() || tx.empty())
        return fail(-EINVAL);
    if (tx.size() > kMaxTransfer)
        return fail(-EMSGSIZE);

    int r;
    if (config_.byte_delay_us == 0) {
        spi_ioc_transfer t{}; // unused and future fields must be zero (spidev.h)
        t.tx_buf = user_ptr(tx.data());
        t.rx_buf = user_ptr(rx.data());
        t.len = static_cast<__u32>(tx.size());
        t.speed_hz = config_.speed_hz;
        t.bits_per_word = 8;
        r = io_.ioctl(fd_, SPI_IOC_MESSAGE(1), &t);
    } else {
        if (tx.size() > kMaxPerByteTransfers)
            return fail(-EMSGSIZE);
        // One transfer per byte with cs_change 0: chip select stays asserted for the whole
        // frame, and delay_usecs pauses the clock after every byte.
        std::array<spi_ioc_transfer, kMaxPerByteTransfers> ts{};
        for (size_t i = 0; i < tx.size(); ++i) {
            spi_ioc_transfer& t = ts[i];
            t.tx_buf = user_ptr(tx.data() + i);
            t.rx_buf = user_ptr(rx.data() + i);
            t.len = 1;
            t.speed_hz = config_.speed_hz;
            t.delay_usecs = config_.byte_delay_us;
            t.bits_per_word = 8;
        }
        r = io_.ioctl(fd_, spi_message_request(tx.size()), ts.data());
    }
    if (r < 0)
        return fail(r);
    // spidev returns the number of bytes moved; anything short means the frame is torn.
    if (static_cast<size_t>(r) != tx.size())
        return fail(-EIO);
    return 0;
}

} // namespace caracara
