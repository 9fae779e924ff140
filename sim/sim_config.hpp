// caracara-sim's description of the vehicle it plays: device nodes, bus clock, thrusters.
// The [[thruster]] tables use the same keys as caracarad.toml so one file can describe both.
#pragma once

#include "core/vehicle_geometry.hpp"
#include "sim/teensy_config.hpp"
#include "sim/thruster_model.hpp"

#include <array>

#include <string>
#include <vector>

namespace caracara::sim {

struct SimConfig {
    std::string i2c_device = "/dev/i2c-1";
    uint32_t i2c_clock_hz = 100000;
    bool realistic_timing = false;
    std::string spi_device = "/dev/spidev0.0";
    std::vector<ThrusterSpec> thrusters;
    // The I2C controller's platform driver, as sysfs shows it on the SBC.
    std::string unbind_path = "/sys/bus/platform/drivers/i2c-bcm2835/unbind";
    std::string bind_path = "/sys/bus/platform/drivers/i2c-bcm2835/bind";
    std::string driver_id = "fe804000.i2c";
    uint32_t rebind_delay_ms = 20; // udev recreating /dev/i2c-N after a bind
    bool kill_switch_active_low = false;
    // The wire log keeps this many entries, oldest dropped first: a long soak stays bounded.
    uint32_t wire_log_entries = 200000;
    // How the thrusters sit on the hull, which caracarad cannot see (commissioning finds it):
    // a thruster mounted reversed pushes the body the other way; a disconnected one (motor
    // lead off, controller still answering) pushes nothing. Indexed by motor 0..7.
    std::array<bool, 8> mounted_reversed{};
    std::array<bool, 8> disconnected{};
    // The Teensy's orientation sensor noise and drift, among its other settings.
    TeensyConfig teensy;
    // [vehicle] and the thrusters' position / direction, as caracara-ros reads them: with a mass
    // (and an inertia) the body moves in newtons (sim/vehicle_body.hpp).
    VehicleGeometry vehicle;
};

SimConfig default_sim_config();
// Parses a TOML file; returns false with a message naming the key on error. Keys of
// caracarad.toml that do not concern the simulator are ignored.
bool load_sim_config(const std::string& path, SimConfig& out, std::string& error);
bool parse_sim_config(const std::string& text, SimConfig& out, std::string& error);

} // namespace caracara::sim
