// A VehicleDaemon in process on the fakes of the device seam (FakeDeviceIo, FakeGpio), with
// its own sd-event loop that a test runs for as long as it needs: the daemon's objects as
// they run in caracarad, without D-Bus and without any process.
#pragma once

#include "daemon/vehicle_daemon.hpp"
#include "tests/unit/fakes/fake_device_io.hpp"
#include "tests/unit/fakes/fake_gpio.hpp"
#include "tests/unit/fakes/fake_wire.hpp"

#include <functional>
#include <memory>
#include <string>

namespace caracara::test {

class DaemonRig {
public:
    // `control`: the [control] section's lines (armed at start unless they say arm_at_start, no
    // arming delay by default); `sections`: more tables, whole (e.g. "[failsafe.pilot-lost]\n
    // persistence_ms = 300\n"; the Teensy is not fitted unless they have an [spi]);
    // `kill_switch_set`: the switch as the daemon finds it at start; `spi_io`: the Teensy's side
    // of the seam (FakeTeensyIo, outliving the rig; null: no Teensy's node).
    explicit DaemonRig(const std::string& control = "loop_rate_hz = 50\n", const std::string& sections = "",
                       bool kill_switch_set = false, DeviceIo* spi_io = nullptr);
    ~DaemonRig();

    VehicleDaemon& daemon() { return *daemon_; }
    Vehicle& vehicle() { return daemon_->vehicle(); }
    PacketHandler& packets() { return daemon_->packets(); }
    ControlLoop& loop() { return daemon_->loop(); }
    const DaemonConfig& config() const { return config_; }
    FakeWire& wire() { return wire_; }
    FakeGpio& gpio() { return gpio_; }
    sd_event* event() { return event_; }

    // Runs the loop until `done()` or `timeout_ms` passed; returns done().
    bool run_until(const std::function<bool()>& done, int timeout_ms = 3000);
    void run_for(int ms);
    // Until the vehicle is ready (arming over) and every thruster was ordered at least once.
    void run_until_ready();

private:
    FakeWire wire_;
    DaemonConfig config_;
    FakeDeviceIo io_;
    FakeGpio gpio_;
    sd_event* event_ = nullptr;
    std::unique_ptr<VehicleDaemon> daemon_;
};

// The motor value a thruster receives for `v`: its speed byte's meaning (IDS 6.2 steps).
int32_t on_wire(int32_t v);
// The index of the first event at or after `from` that `match` accepts, or -1.
long find(const std::vector<WireEvent>& events, const std::function<bool(const WireEvent&)>& match, long from = 0);

} // namespace caracara::test
