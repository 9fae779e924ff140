// The steps of recovering a locked I2C bus (NXP UM10204 section 3.1.16 "Bus clear"; Linux
// i2c_generic_scl_recovery), each run at once on the loop thread while no transfer is out:
// close the adapter, unbind its platform driver, clock SCL through the GPIO lines until SDA is
// released and send a STOP, rebind, open the device node again. The emergency stop's
// connection to the node (an I2cNodeHolder) is let go while the driver is unbound and taken
// again once the node is back. When to run them, and what a failure means, is BusRecovery's.
#pragma once

#include "core/config.hpp"
#include "daemon/bus/thruster_bus.hpp"
#include "drivers/devices/i2c_bus_clear.hpp"
#include "drivers/devices/i2c_node_holder.hpp"
#include "drivers/platform/device_io.hpp"
#include "drivers/platform/gpio_backend.hpp"

#include <string>

namespace caracara {

class BusRecoverySteps {
public:
    BusRecoverySteps(const DaemonConfig& config, DeviceIo& io, GpioBackend& gpio, ThrusterBus& bus)
        : config_(config), io_(io), gpio_(gpio), bus_(bus) {}

    // Null: none.
    void set_node_holder(I2cNodeHolder* holder) { node_holder_ = holder; }

    // Close, unbind, bus clear, rebind.
    BusClearResult clear();
    // Opens the adapter's node again (0, and the node holder re-armed) or returns -errno.
    int open_node();
    // Close and open the adapter's node anew (an adapter that went away), the holder with it.
    void reopen_adapter();

private:
    void close_adapter();
    void release_node_holder();
    void reopen_node_holder();

    const DaemonConfig& config_;
    DeviceIo& io_;
    GpioBackend& gpio_;
    ThrusterBus& bus_;
    I2cNodeHolder* node_holder_ = nullptr;
};

} // namespace caracara
