// Carries out what the safety machine decided (a SafetyAction) on the hardware. Every kill (Kill,
// a packet's kill, the kill switch, a failsafe, a lost device, power-off) takes one sequence,
// `carry_out` with the reason a running turn ends: the bus held, the kill output (one GPIO
// write), the zeros on the bus (through the DemandListener, the loop) in front of anything
// queued, the wheels stopped, the turn ended. The power-off line goes once the zeros are on
// the wire.
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

    // `kill_output_asserted`: what the safety machine says after the action. `kill`: the action
    // is a kill (the reason a running turn ends), or null (arming, a tick, a timeout, a client
    // that left).
    void carry_out(const SafetyAction& a, bool kill_output_asserted, const Result* kill);
    // The orders standing now, down to the thrusters.
    void hand_down(const MotorValues& orders) { orders_->demand_changed(orders); }
    // Thrusters to zero first, then the power-off line once the zeros are on the wire.
    void power_off();
    // `done(r)` once the transfers handed to the bus so far are on the wire.
    void after_zeros(Completion done, Result r);

private:
    ThrusterBus& bus_;
    SafetyLines& lines_;
    TeensyPort& teensy_;
    DemandListener* orders_ = nullptr;
};

} // namespace caracara
