// Recovering a locked I2C bus: the steps (BusRecoverySteps: close, unbind, bus clear, rebind),
// then wait for the device node, re-send the current orders (a pending kill first). Bounded
// attempts with backoff (RecoveryPolicy); when they are used up, or the lockup outlasts the
// command timeout, the bus is reported lost (BusLoss), and slow retries go on in the
// background. Owns its timer.
#pragma once

#include "core/config.hpp"
#include "core/recovery_policy.hpp"
#include "daemon/recovery/bus_loss.hpp"
#include "daemon/recovery/bus_recovery_steps.hpp"
#include "daemon/bus/thruster_bus.hpp"
#include "daemon/control/control_loop.hpp"
#include "daemon/interfaces/failsafe_gate.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "drivers/platform/device_io.hpp"
#include "drivers/platform/event_loop.hpp"
#include "drivers/platform/gpio_backend.hpp"

#include <cstdint>
#include <string>

namespace caracara {

class BusRecovery final : public BusMonitor::Listener {
public:
    BusRecovery(sd_event* event, const DaemonConfig& config, DeviceIo& io, GpioBackend& gpio, ThrusterBus& bus,
                ControlLoop& loop, FailsafeGate& failsafes, VehicleEvents& events);

    void bus_locked_up(const std::string& reason) override;
    void bus_back() override { loss_.recovered(); }
    // The other holder of the I2C node (the emergency stop's connection), let go of while the
    // driver is unbound and taken again once it is back. Null: none.
    void set_node_holder(I2cNodeHolder* holder) { steps_.set_node_holder(holder); }
    void stop() {
        timer_.reset();
        loss_.stop();
    }

private:
    enum class Phase { Idle, WaitingNode, Verifying, Backoff, Reopening };
    static int on_timer(sd_event_source*, uint64_t usec, void* userdata);
    void schedule(uint64_t delay_ns);
    void attempt();
    void wait_node();
    void finish();
    void verify(); // once the re-sent orders are done: did any thruster answer?
    void reopen(); // lost without recovery configured: the adapter's node opened anew
    void failed(const std::string& why);

    sd_event* event_;
    const DaemonConfig& config_;
    ThrusterBus& bus_;
    BusRecoverySteps steps_;
    ControlLoop& loop_; // the orders standing now, re-sent once the bus is back
    VehicleEvents& events_;
    BusLoss loss_;
    RecoveryPolicy policy_;
    Phase phase_ = Phase::Idle;
    uint64_t node_deadline_ns_ = 0;
    uint32_t last_pulses_ = 0;
    SourcePtr timer_;
};

} // namespace caracara
