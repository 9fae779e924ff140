// Declaring the I2C bus lost: the thrusters cannot be reached, so bus-lost is pushed to the
// failsafes (they kill, source bus; the bus keeps the kill until it is back), and its end when
// the bus is back. A lockup under recovery that outlasts the
// command timeout is a lost bus too: it has left the thrusters unreachable for longer than any
// command may stand. Owns that timer; when to recover is BusRecovery's.
#pragma once

#include "core/config.hpp"
#include "daemon/bus/thruster_bus.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "daemon/interfaces/failsafe_gate.hpp"
#include "drivers/platform/event_loop.hpp"

#include <cstdint>
#include <string>

namespace caracara {

class BusLoss {
public:
    BusLoss(sd_event* event, const ControlSettings& control, ThrusterBus& bus, FailsafeGate& failsafes,
            VehicleEvents& events)
        : event_(event), control_(control), bus_(bus), failsafes_(failsafes), events_(events) {}

    // A lockup is being recovered: lost if the bus is still recovering after the command timeout.
    void watch();
    // The bus is back: the command timeout no longer runs, and a lost bus's bus-lost clears.
    void recovered();
    // Bus state Lost, bus-lost pushed (the kill); nothing if the bus already is.
    void declare(const std::string& why);
    void stop() { timer_.reset(); }

private:
    static int on_timer(sd_event_source*, uint64_t usec, void* userdata);

    sd_event* event_;
    const ControlSettings& control_;
    ThrusterBus& bus_;
    FailsafeGate& failsafes_;
    VehicleEvents& events_;
    SourcePtr timer_;
    bool pushed_ = false; // bus-lost holds, as pushed
};

} // namespace caracara
