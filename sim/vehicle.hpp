// The whole simulated vehicle: device nodes, buses, devices, physics, wire log. The device
// server and the inspection API both work on this one object.
#pragma once

#include "i2c_bus_model.hpp"
#include "sim_config.hpp"
#include "slave.hpp"
#include "teensy_model.hpp"
#include "thruster_model.hpp"
#include "vehicle_body.hpp"
#include "wire_log.hpp"

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace caracara::sim {

struct SpiMessageXfer {
    std::vector<uint8_t> tx;  // empty when the transfer had no tx_buf (the master sends zeros)
    size_t len = 0;
    bool want_rx = false;
    SpiTransferParams params;
    std::vector<uint8_t> rx;  // filled by the vehicle
};

struct SpiPort {
    SpiSlave* slave = nullptr;
    uint8_t mode = 0;
    uint8_t bits_per_word = 8;
    uint32_t max_speed_hz = 500000;
    uint8_t lsb_first = 0;
    uint64_t messages = 0;
    uint64_t mode_mismatches = 0;
};

class SimVehicle {
public:
    explicit SimVehicle(const SimConfig& cfg);

    enum class NodeKind { None, I2c, Spi };
    NodeKind node_kind(const std::string& path) const;

    I2cBusModel& i2c() { return i2c_; }
    const std::string& i2c_path() const { return cfg_.i2c_device; }
    SpiPort* spi_port(const std::string& path);
    void attach_spi(const std::string& path, SpiSlave* slave);
    // One SPI_IOC_MESSAGE: returns total bytes or -errno, and the wire time.
    int spi_message(SpiPort& port, std::vector<SpiMessageXfer>& xfers, uint64_t start_ns, uint64_t& wire_ns);

    std::vector<std::unique_ptr<ThrusterModel>>& thrusters() { return thrusters_; }
    VehicleBody& body() { return *body_; }
    TeensyModel& teensy() { return *teensy_; }
    WireLog& log() { return log_; }
    void add_stepped(Stepped* s) { stepped_.push_back(s); }
    void step(double dt_s, uint64_t now_ns);

    bool realistic_timing() const { return realistic_; }
    void set_realistic_timing(bool on) { realistic_ = on; }
    // Real-time mode: the wire is busy until this time; the next transaction starts after it.
    uint64_t& bus_free_at() { return bus_free_at_; }

private:
    SimConfig cfg_;
    WireLog log_;
    I2cBusModel i2c_;
    std::vector<std::unique_ptr<ThrusterModel>> thrusters_;
    std::map<std::string, SpiPort> spi_;
    std::unique_ptr<VehicleBody> body_;
    std::unique_ptr<TeensyModel> teensy_;
    std::vector<Stepped*> stepped_;
    bool realistic_ = false;
    uint64_t bus_free_at_ = 0;
};

} // namespace caracara::sim
