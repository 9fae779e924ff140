// caracara-sim's front end for a real Linux kernel: serves /dev/caracara-bridge, the
// character device of the test kernel module tests/kernel/module/caracara_bridge.c, with
// the vehicle's models. The kernel's own i2c-dev, spidev and GPIO character device are then
// what caracarad --hardware=linux talks to; every I2C transfer, SPI message and GPIO line
// operation they make reaches the same bus, Teensy and GPIO models (and wire log) as the
// device socket does. Protocol: sim/kernel_bridge_abi.h, docs/kernel-bridge.md.
#pragma once

#include "drivers/sdbus/sdbus.hpp"
#include "sim/sim_config.hpp"
#include "sim/sim_vehicle.hpp"

#include <cstdint>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace caracara::sim {

class KernelBridge {
public:
    KernelBridge(sd_event* event, SimVehicle& vehicle, const SimConfig& cfg);
    ~KernelBridge();
    KernelBridge(const KernelBridge&) = delete;
    KernelBridge& operator=(const KernelBridge&) = delete;

    // Opens the bridge device and starts serving it; -errno.
    int open(const std::string& device);
    uint64_t requests() const { return requests_; }
    uint64_t bad_requests() const { return bad_requests_; }

private:
    static int on_io(sd_event_source*, int fd, uint32_t revents, void* userdata);
    // Builds the reply to one request into reply_ (empty for none).
    void handle(std::span<const uint8_t> req);
    void handle_i2c(std::span<const uint8_t> payload, int32_t& result);
    void handle_spi(std::span<const uint8_t> payload, int32_t& result);
    int32_t handle_gpio(uint16_t op, std::span<const uint8_t> payload);
    void push_level(uint32_t offset, int level);
    void send(uint16_t type, uint32_t seq, uint16_t arg, int32_t result, std::span<const uint8_t> payload);

    sd_event* event_;
    SimVehicle& vehicle_;
    SimConfig cfg_;
    int fd_ = -1;
    dbus::SourcePtr io_;
    std::vector<uint8_t> buf_;
    std::vector<uint8_t> payload_;
    // Model line index -> the mode the kernel put it in (it is requested in the model).
    std::map<int, GpioMode> modes_;
    // The GPIO model's change callback before open() chained onto it; restored on destruction.
    std::function<void(int, int, uint64_t)> previous_on_change_;
    bool hooked_ = false;
    uint64_t requests_ = 0;
    uint64_t bad_requests_ = 0;
};

} // namespace caracara::sim
