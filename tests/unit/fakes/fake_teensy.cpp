#include "tests/unit/fakes/fake_teensy.hpp"

#include "core/clock.hpp"

#include <algorithm>
#include <cerrno>
#include <linux/spi/spidev.h>
#include <span>

namespace caracara::test {

FakeTeensy::FakeTeensy(sim::TeensyModel::AttitudeSource attitude, std::string device)
    : device_(std::move(device)), model_(sim::TeensyConfig{}, std::move(attitude)) {}

int FakeTeensy::open(const char* path, int) {
    return device_ == path ? kSpiFd : -ENOENT;
}

int FakeTeensy::ioctl(int fd, unsigned long request, void* arg) {
    if (fd != kSpiFd)
        return -EBADF;
    if (request == SPI_IOC_WR_MODE || request == SPI_IOC_WR_BITS_PER_WORD || request == SPI_IOC_WR_MAX_SPEED_HZ)
        return 0;
    if (_IOC_TYPE(request) == SPI_IOC_MAGIC && _IOC_NR(request) == 0 && _IOC_DIR(request) == _IOC_WRITE)
        return message(request, arg);
    return -ENOTTY;
}

int FakeTeensy::message(unsigned long request, void* arg) {
    const std::size_t n = _IOC_SIZE(request) / sizeof(spi_ioc_transfer);
    auto* t = static_cast<spi_ioc_transfer*>(arg);
    std::lock_guard lk(mu_);
    const uint64_t now = monotonic_ns();
    int total = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const auto* tx = reinterpret_cast<const uint8_t*>(static_cast<uintptr_t>(t[i].tx_buf));
        auto* rx = reinterpret_cast<uint8_t*>(static_cast<uintptr_t>(t[i].rx_buf));
        sim::SpiTransferParams p{t[i].speed_hz, t[i].delay_usecs, t[i].bits_per_word, t[i].cs_change != 0};
        if (silent_)
            std::fill_n(rx, t[i].len, uint8_t{0});
        else
            model_.transfer({tx, t[i].len}, {rx, t[i].len}, p, now);
        total += static_cast<int>(t[i].len);
    }
    if (!silent_)
        model_.end_message(now);
    return total;
}

void FakeTeensy::set_silent(bool silent) {
    std::lock_guard lk(mu_);
    silent_ = silent;
}

} // namespace caracara::test
