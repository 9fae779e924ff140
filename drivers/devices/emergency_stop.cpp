#include "drivers/devices/emergency_stop.hpp"
#include "drivers/protocol/pca9544a.hpp"

#include "drivers/platform/io_error.hpp"
#include "drivers/protocol/seabotix.hpp"

#include <csignal>
#include <fcntl.h>
#include <linux/i2c-dev.h>

namespace caracara {

std::string EmergencyStop::arm(std::unique_ptr<DeviceIo> io, const std::string& i2c_path,
                               std::span<const ThrusterConfig> thrusters, const SpiSettings& spi) {
    if (thrusters.size() > prepared_.size())
        return "too many thrusters";
    int fd = io->open(i2c_path.c_str(), O_RDWR);
    if (fd < 0)
        return "cannot open " + i2c_path + ": " + errno_name(-fd);
    for (size_t i = 0; i < thrusters.size(); ++i) {
        const ThrusterConfig& c = thrusters[i];
        auto order = encode_order(c.mt, kSpeedStop, c.info);
        if (!order) {
            io->close(fd);
            return "thruster " + std::to_string(i) + ": cannot encode a zero order";
        }
        Prepared& p = prepared_[i];
        p.order = *order;
        p.addr7 = mt_addr7(c.mt);
        p.has_mux = c.mux.has_value();
        if (p.has_mux) {
            p.mux_addr7 = c.mux->addr7;
            p.mux_control = mux_control_byte(c.mux->channel);
        }
    }
    count_ = thrusters.size();
    io_ = std::move(io);
    path_ = i2c_path;
    fd_ = fd;
    if (auto stop = teensy::encode_stop(0); stop.ok()) {
        auto dev = std::make_unique<SpiDev>(*io_, spi.device, spi.spi);
        if (dev->open() == 0) {
            stop_frame_ = stop.value;
            spi_ = std::move(dev);
        }
    }
    return {};
}

void EmergencyStop::release() {
    const int fd = fd_;
    if (fd < 0)
        return;
    fd_ = -1; // first, so a signal arriving now does not use a closed descriptor
    io_->close(fd);
}

std::string EmergencyStop::reopen() {
    if (!io_ || fd_ >= 0)
        return {};
    int fd = io_->open(path_.c_str(), O_RDWR);
    if (fd < 0)
        return "cannot open " + path_ + ": " + errno_name(-fd);
    fd_ = fd;
    return {};
}

void EmergencyStop::fire() noexcept {
    gate_.close();
    if (GpioLine* line = kill_output_.load())
        line->set_in_signal_handler(1);
    const int fd = fd_;
    if (fd < 0)
        return;
    gate_.wait_clear(kGateWaitMs);
    for (size_t i = 0; i < count_; ++i) {
        Prepared& p = prepared_[i];
        if (p.has_mux) {
            i2c_msg sel{p.mux_addr7, 0, 1, &p.mux_control};
            i2c_rdwr_ioctl_data d{&sel, 1};
            io_->ioctl(fd, I2C_RDWR, &d);
        }
        i2c_msg m{p.addr7, 0, static_cast<__u16>(p.order.size()), p.order.data()};
        i2c_rdwr_ioctl_data d{&m, 1};
        io_->ioctl(fd, I2C_RDWR, &d);
    }
    // Other muxes may still have a channel on; the next daemon instance sorts that out.
    if (spi_) // SpiDev::transfer allocates nothing; one try, no busy retries
        spi_->transfer(stop_frame_.span(), std::span<uint8_t>(stop_reply_.data(), stop_frame_.size));
}

namespace {
EmergencyStop* g_stop = nullptr;

void on_fatal(int sig) {
    EmergencyStop* s = g_stop;
    g_stop = nullptr; // once: a crash inside fire() must not loop
    if (s)
        s->fire();
    signal(sig, SIG_DFL);
    raise(sig);
}
} // namespace

void EmergencyStop::install_fatal_handlers(EmergencyStop* stop) {
    g_stop = stop;
    struct sigaction sa {};
    sa.sa_handler = on_fatal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND | SA_NODEFER;
    for (int sig : kFatalSignals)
        sigaction(sig, &sa, nullptr);
}

} // namespace caracara
