// The whole simulated vehicle: device nodes, buses, devices, physics, wire log. The device
// server and the inspection API both work on this one object.
#pragma once

#include "sim/gpio_model.hpp"
#include "sim/i2c_bus_model.hpp"
#include "sim/sim_config.hpp"
#include "sim/spi_message_xfer.hpp"
#include "sim/spi_port.hpp"
#include "sim/spi_slave.hpp"
#include "sim/stepped.hpp"
#include "sim/teensy_model.hpp"
#include "sim/thruster_model.hpp"
#include "sim/vehicle_body.hpp"
#include "sim/wire_log.hpp"

#include <algorithm>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace caracara::sim {

class SimVehicle {
public:
    explicit SimVehicle(const SimConfig& cfg);

    enum class NodeKind { None, I2c, Spi, Unbind, Bind };
    NodeKind node_kind(const std::string& path, uint64_t now_ns) const;
    // The I2C adapter exists (driver bound and its device node recreated).
    bool i2c_present(uint64_t now_ns) const { return bound_ && now_ns >= node_back_at_ && now_ns >= i2c_gone_until_; }
    // A write to the driver's sysfs bind/unbind attribute. Bytes consumed or -errno.
    int sysfs_write(NodeKind which, std::string_view data, uint64_t now_ns);
    bool driver_bound() const { return bound_; }
    // A device node that vanishes (hot unplug, its driver gone) for `ms` and then returns: the
    // handles opened before stay dead (ENODEV, as the kernel's do), opening it fails with
    // ENOENT until it is back. kind: I2c (the adapter) or Spi (every SPI device).
    void vanish(NodeKind kind, uint32_t ms, uint64_t now_ns);
    bool vanished(NodeKind kind, uint64_t now_ns) const;
    // Bumped at each vanish: a handle remembers the epoch it was opened in.
    uint32_t node_epoch(NodeKind kind) const { return kind == NodeKind::Spi ? spi_epoch_ : i2c_epoch_; }
    uint64_t unbinds() const { return unbinds_; }
    uint64_t binds() const { return binds_; }
    GpioModel& gpio() { return gpio_; }

    I2cBusModel& i2c() { return i2c_; }
    const std::string& i2c_path() const { return cfg_.i2c_device; }
    SpiPort* spi_port(const std::string& path);
    void attach_spi(const std::string& path, SpiSlave* slave);
    // One SPI_IOC_MESSAGE: returns total bytes or -errno, and the wire time.
    int spi_message(SpiPort& port, std::vector<SpiMessageXfer>& xfers, uint64_t start_ns, uint64_t& wire_ns);

    std::vector<std::unique_ptr<ThrusterModel>>& thrusters() { return thrusters_; }
    VehicleBody& body() { return *body_; }
    TeensyModel& teensy() { return *teensy_; }
    SpiPort& teensy_port() { return spi_[cfg_.spi_device]; }
    WireLog& log() { return log_; }
    void add_stepped(Stepped* s) { stepped_.push_back(s); }
    void step(double dt_s, uint64_t now_ns);

    // What the daemon set with I2C_TIMEOUT (10 ms units) and I2C_RETRIES; -1: never set.
    int64_t i2c_timeout = -1;
    int64_t i2c_retries = -1;

    bool realistic_timing() const { return realistic_; }
    void set_realistic_timing(bool on) { realistic_ = on; }
    // Real-time mode: the wire is busy until this time; the next transaction starts after it.
    uint64_t& bus_free_at() { return bus_free_at_; }
    // When a transaction asked for at `now_ns` starts on the wire: at once, or in real-time
    // mode once the one before it is over.
    uint64_t wire_start(uint64_t now_ns) const { return realistic_ ? std::max(now_ns, bus_free_at_) : now_ns; }
    // The SPI bus is a wire of its own (another controller on the SBC): a Teensy frame never
    // waits for an I2C transaction, nor the other way round.
    uint64_t& spi_free_at() { return spi_free_at_; }
    uint64_t spi_wire_start(uint64_t now_ns) const { return realistic_ ? std::max(now_ns, spi_free_at_) : now_ns; }

private:
    SimConfig cfg_;
    WireLog log_{cfg_.wire_log_entries};
    I2cBusModel i2c_;
    std::vector<std::unique_ptr<ThrusterModel>> thrusters_;
    std::map<std::string, SpiPort> spi_;
    std::unique_ptr<VehicleBody> body_;
    std::unique_ptr<TeensyModel> teensy_;
    std::vector<Stepped*> stepped_;
    GpioModel gpio_;
    bool bound_ = true;
    uint64_t node_back_at_ = 0;
    uint64_t i2c_gone_until_ = 0;
    uint64_t spi_gone_until_ = 0;
    uint32_t i2c_epoch_ = 0;
    uint32_t spi_epoch_ = 0;
    uint64_t unbinds_ = 0;
    uint64_t binds_ = 0;
    bool realistic_ = false;
    uint64_t bus_free_at_ = 0;
    uint64_t spi_free_at_ = 0;
};

} // namespace caracara::sim
