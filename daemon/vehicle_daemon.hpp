// Owns the daemon's objects and brings them up and down in the order safety needs: the I2C
// bus opened and every thruster zeroed before anything else, then the safety lines, the
// Teensy, the loop; on the way out the loop stopped and every thruster zeroed again.
#pragma once

#include "core/config.hpp"
#include "daemon/bus/thruster_bus.hpp"
#include "daemon/commissioning/bus_scan.hpp"
#include "daemon/commissioning/direction_detection.hpp"
#include "daemon/commissioning/motor_test.hpp"
#include "daemon/commissioning/preflight.hpp"
#include "daemon/control/control_loop.hpp"
#include "daemon/dive/dive_recorder.hpp"
#include "daemon/dive/dive_writer.hpp"
#include "daemon/failsafe/failsafe_monitor.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "daemon/recovery/bus_recovery.hpp"
#include "daemon/safety/safety_lines.hpp"
#include "daemon/service_status.hpp"
#include "daemon/teensy/teensy_port.hpp"
#include "daemon/vehicle/packet_handler.hpp"
#include "daemon/vehicle/vehicle.hpp"
#include "drivers/devices/emergency_stop.hpp"
#include "drivers/platform/device_io.hpp"
#include "drivers/platform/gpio_backend.hpp"

#include <memory>
#include <string>

namespace caracara {

class VehicleDaemon {
public:
    // `bus_io` carries the I2C transfers on the bus worker's thread, `spi_io` the Teensy's frames
    // on the Teensy worker's; `io` everything else.
    VehicleDaemon(sd_event* event, DeviceIo& io, DeviceIo& bus_io, DeviceIo& spi_io, GpioBackend& gpio,
                  DaemonConfig config);
    ~VehicleDaemon() { shutdown(); }
    VehicleDaemon(const VehicleDaemon&) = delete;
    VehicleDaemon& operator=(const VehicleDaemon&) = delete;

    // "" or the reason the daemon cannot run (the I2C bus or a configured GPIO line cannot be
    // had). A missing Teensy is not fatal.
    std::string start();
    // Orders zero to every thruster (SIGTERM, fatal errors). Safe to call more than once.
    void shutdown();
    // An armed emergency stop, made before the daemon so that it outlives it: the bus worker
    // enters its gate, the safety lines tell it the kill output, a bus recovery lets go of
    // its I2C node while the adapter is rebound.
    void attach_emergency_stop(EmergencyStop& stop);

    const DaemonConfig& config() const { return config_; }
    VehicleEvents& events() { return events_; }
    Vehicle& vehicle() { return vehicle_; }
    const Vehicle& vehicle() const { return vehicle_; }
    PacketHandler& packets() { return packets_; }
    ThrusterBus& bus() { return bus_; }
    const ThrusterBus& bus() const { return bus_; }
    TeensyPort& teensy() { return teensy_; }
    const TeensyPort& teensy() const { return teensy_; }
    ControlLoop& loop() { return loop_; }
    const ControlLoop& loop() const { return loop_; }
    ServiceStatus& status() { return status_; }
    MotorTest& motor_test() { return motor_test_; }
    const MotorTest& motor_test() const { return motor_test_; }
    DirectionDetection& directions() { return directions_; }
    Preflight& preflight() { return preflight_; }
    BusScan& bus_scan() { return bus_scan_; }
    FailsafeMonitor& failsafes() { return failsafes_; }
    const FailsafeMonitor& failsafes() const { return failsafes_; }
    // The dive recorder, or nullptr when recorder.enabled is false.
    const DiveRecorder* recorder() const { return recorder_.get(); }

private:
    // Thruster i's last good status reply, for the failsafes; nullopt while it does not answer.
    std::optional<FailsafeReading> reading(std::size_t i) const;

    sd_event* event_;
    DaemonConfig config_;
    VehicleEvents events_;
    ThrusterBus bus_;
    SafetyLines lines_;
    TeensyPort teensy_;
    Vehicle vehicle_;
    PacketHandler packets_;
    ControlLoop loop_;
    BusRecovery recovery_;
    ServiceStatus status_;
    FailsafeMonitor failsafes_;
    MotorTest motor_test_;
    DirectionDetection directions_;
    Preflight preflight_;
    BusScan bus_scan_;
    std::unique_ptr<DiveWriter> dive_writer_;
    std::unique_ptr<DiveRecorder> recorder_;
    bool started_ = false;
};

} // namespace caracara
