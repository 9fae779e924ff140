// Carries out what the safety machine decided (a SafetyAction) on the hardware, in the order
// docs/architecture.md gives: the kill output first (one GPIO write), then the zeros on the
// bus (through the DemandListener, the loop), then the wheels; and the power-off line once
// the zeros are on the wire.
#pragma once

#include "core/motor_demand.hpp"
#include "core/safety.hpp"
#include "core/status.hpp"
#include "daemon/bus/thruster_bus.hpp"
#include "daemon/loop/completion.hpp"
#include "daemon/safety/safety_lines.hpp"
#include "daemon/teensy/teensy_port.hpp"
#include "daemon/interfaces/demand_listener.hpp"

namespace caracara {

class SafetyActuator final {
public:
    SafetyActuator(ThrusterBus& bus, SafetyLines& lines, TeensyPort& teensy)
        : bus_(bus), lines_(lines), teensy_(teensy) {}
    // Where the motor values go down to the thrusters (the control loop).
    void set_demand_listener(DemandListener* orders) { orders_ = orders; }

    // `kill_output_asserted`: what the safety machine says after the action.
    void carry_out(const SafetyAction& a, bool kill_output_asserted);
    // The orders standing now, down to the thrusters.
    void hand_down(const MotorValues& orders) { orders_->demand_changed(orders); }
    // Thrusters to zero first, then the power-off line once the zeros are on the wire.
    void power_off();
    // The wheels: stop a motion, and tell a running turn why it ends.
    void stop_wheels() { teensy_.stop_motion(); }
    void cancel_turn(const Result& why) { teensy_.cancel_turn(why); }
    // `done(r)` once the transfers handed to the bus so far are on the wire.
    void after_zeros(Completion done, Result r);

private:
    ThrusterBus& bus_;
    SafetyLines& lines_;
    TeensyPort& teensy_;
    DemandListener* orders_ = nullptr;
};

} // namespace caracara
