// Zero orders for every thruster, prepared in advance on a device connection of their own, so
// a fatal signal handler can send them without allocating, locking or touching state the
// crash may have left half-written. Only async-signal-safe calls happen in fire(). The kill
// output is asserted first (a run enable: one GPIO write, before any bus transfer); the
// Teensy's wheels are motors too: a prepared Stop frame goes out after the zero orders.
#pragma once

#include "drivers/platform/device_io.hpp"
#include "core/config.hpp"
#include "drivers/devices/bus_gate.hpp"
#include "drivers/devices/i2c_node_holder.hpp"
#include "drivers/devices/kill_output_watcher.hpp"
#include "drivers/devices/thruster_driver.hpp"
#include "drivers/platform/gpio_line.hpp"
#include "drivers/platform/spi_dev.hpp"
#include "drivers/protocol/teensy_codec.hpp"

#include <array>
#include <atomic>
#include <csignal>
#include <linux/i2c.h>
#include <memory>
#include <span>
#include <string>

namespace caracara {

class EmergencyStop final : public KillOutputWatcher, public I2cNodeHolder {
public:
    // Opens `i2c_path` on `io` (its own connection / file description) and encodes a zero order
    // per thruster, with its mux select; and, when the Teensy's SPI device opens, a Stop for
    // its wheels (a missing Teensy is not an error). Returns "" or why it could not.
    std::string arm(std::unique_ptr<DeviceIo> io, const std::string& i2c_path, std::span<const ThrusterConfig> thrusters,
                    const SpiSettings& spi);
    // Asserts the kill output, then sends the zero orders. Async-signal-safe; errors are ignored
    // (there is no one to tell).
    void fire() noexcept;
    // The kill output line as SafetyLines holds it now (null while it has none): set before the
    // line is made and cleared before it is destroyed, so fire() never sees a dead one.
    void set_kill_output(GpioLine* line) noexcept override { kill_output_.store(line); }
    // Closes the prepared connection while the I2C adapter's driver is unbound and rebound:
    // the kernel's i2c_del_adapter() waits until every open /dev/i2c-N is closed, so a file
    // kept open here would hang the unbinding write (and the daemon) for good. fire() does
    // nothing until reopen().
    void release() override;
    // Opens the node again after the rebind; "" or why not (then it stays released).
    std::string reopen() override;
    bool armed() const { return fd_ >= 0; }
    // The daemon's bus worker enters this gate for each transfer; fire() closes it before the
    // kill output and waits (at most kGateWaitMs) for the transfer on the wire before its zeros.
    BusGate& bus_gate() noexcept { return gate_; }
    // Longer than the adapter's timeout (i2c.timeout_ms, 20 by default), so a transfer to a hung
    // thruster ends first; past it the zeros go anyway.
    static constexpr int kGateWaitMs = 100;

    // Every signal whose default action ends the process and that the daemon does not handle
    // itself (SIGTERM, SIGINT and SIGHUP stop it cleanly through the event loop; SIGPIPE is
    // ignored): crashes, and stray signals such as SIGQUIT or SIGUSR1 that would otherwise end it
    // with the thrusters still running.
    static constexpr int kFatalSignals[] = {SIGSEGV, SIGBUS,  SIGILL,  SIGFPE,    SIGABRT, SIGQUIT,  SIGTRAP,
                                            SIGSYS,  SIGXCPU, SIGXFSZ, SIGUSR1,   SIGUSR2, SIGALRM,  SIGVTALRM,
                                            SIGPROF, SIGIO,   SIGPWR,  SIGSTKFLT};
    // Installs handlers for kFatalSignals that fire `stop`, then let the signal take its default
    // course (the process ends, with a core dump where the signal makes one, and systemd restarts
    // the service).
    static void install_fatal_handlers(EmergencyStop* stop);

private:
    struct Prepared {
        std::array<uint8_t, 3> order{};
        uint8_t mux_control = 0;
        uint16_t addr7 = 0;
        uint16_t mux_addr7 = 0;
        bool has_mux = false;
    };
    std::unique_ptr<DeviceIo> io_;
    std::unique_ptr<SpiDev> spi_;
    teensy::Frame stop_frame_;
    std::array<uint8_t, teensy::kMaxFrame> stop_reply_{};
    std::string path_;
    volatile int fd_ = -1; // read by fire() in a signal handler
    std::atomic<GpioLine*> kill_output_{nullptr};
    BusGate gate_;
    std::array<Prepared, 8> prepared_{};
    size_t count_ = 0;
};

} // namespace caracara
