#include "tests/unit/fakes/fake_teensy_io.hpp"

#include "core/clock.hpp"

#include <algorithm>
#include <cerrno>
#include <linux/spi/spidev.h>
#include <span>
#include <vector>

namespace caracara::test {

FakeTeensyIo::FakeTeensyIo(std::string device)
    : device_(std::move(device)), model_(sim::TeensyConfig{}, [this] { return attitude_; }) {}

int FakeTeensyIo::open(const char* path, int) {
    std::lock_guard lk(mu_);
    if (device_ != path)
        return -ENOENT;
    return gone_ ? -ENOENT : next_fd_++;
}

int FakeTeensyIo::ioctl(int fd, unsigned long request, void* arg) {
    std::unique_lock lk(mu_);
    released_.wait(lk, [this] { return !held_; });
    if (gone_ || fd < live_from_ || fd >= next_fd_)
        return -ENODEV;
    if (_IOC_TYPE(request) != SPI_IOC_MAGIC)
        return -ENOTTY;
    if (_IOC_NR(request) != 0 || _IOC_DIR(request) != _IOC_WRITE)
        return 0; // the mode, word size and speed: taken
    // SPI_IOC_MESSAGE(n), as the simulator carries it (SimVehicle::spi_message): the model
    // stepped to now first (a running turn), then each transfer, chip select released at the end.
    const uint64_t now = monotonic_ns();
    if (stepped_ns_)
        model_.step(static_cast<double>(now - stepped_ns_) / 1e9, now);
    stepped_ns_ = now;
    const std::size_t n = _IOC_SIZE(request) / sizeof(spi_ioc_transfer);
    auto* ts = static_cast<spi_ioc_transfer*>(arg);
    int total = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const spi_ioc_transfer& t = ts[i];
        std::vector<uint8_t> tx(t.len, 0), rx(t.len, 0);
        if (t.tx_buf)
            std::copy_n(reinterpret_cast<const uint8_t*>(static_cast<uintptr_t>(t.tx_buf)), t.len, tx.begin());
        model_.transfer(tx, rx, {t.speed_hz, t.delay_usecs, t.bits_per_word, t.cs_change != 0}, now);
        if (t.rx_buf)
            std::copy(rx.begin(), rx.end(), reinterpret_cast<uint8_t*>(static_cast<uintptr_t>(t.rx_buf)));
        if (t.cs_change)
            model_.end_message(now);
        total += static_cast<int>(t.len);
    }
    model_.end_message(now);
    return total;
}

void FakeTeensyIo::set_gone(bool gone) {
    std::lock_guard lk(mu_);
    gone_ = gone;
    if (gone)
        live_from_ = next_fd_;
}

void FakeTeensyIo::hold(bool held) {
    {
        std::lock_guard lk(mu_);
        held_ = held;
    }
    released_.notify_all();
}

void FakeTeensyIo::set_attitude(const sim::BodyAttitude& a) {
    std::lock_guard lk(mu_);
    attitude_ = a;
}

void FakeTeensyIo::model(const std::function<void(sim::TeensyModel&)>& f) {
    std::lock_guard lk(mu_);
    f(model_);
}

uint64_t FakeTeensyIo::received(uint8_t command) {
    std::lock_guard lk(mu_);
    return model_.frames().commands_received(command);
}

uint64_t FakeTeensyIo::executed(uint8_t command) {
    std::lock_guard lk(mu_);
    return model_.frames().commands_executed(command);
}

uint64_t FakeTeensyIo::frames() {
    std::lock_guard lk(mu_);
    return model_.frames().total();
}

} // namespace caracara::test
