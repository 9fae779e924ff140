#include "daemon/safety/safety_actuator.hpp"

namespace caracara {

void SafetyActuator::carry_out(const SafetyAction& a, bool kill_output_asserted, const Result* kill) {
    if (kill_output_asserted) {
        // The kill output first: it is one GPIO write, and the zero orders behind it are bus
        // transfers that a hung device can delay. The zeros go before anything queued.
        if (a.state_changed) {
            bus_.worker().hold_orders();
            lines_.set_kill_output(true);
        }
        if (a.zero_outputs)
            orders_->zero_all(ZeroOrder::First);
        // The wheels are motors too; a running turn is told why it ends.
        if (kill) {
            teensy_.stop_motion();
            teensy_.cancel_turn(*kill);
        }
        return;
    }
    // A timeout's or a departed client's zeros go behind what that client had sent; the wheels
    // stop only if they move. Releasing the kill output (arming) waits for the zeros.
    if (a.zero_outputs) {
        orders_->zero_all(ZeroOrder::Behind);
        teensy_.stop_if_moving();
    }
    if (a.state_changed)
        lines_.set_kill_output(false);
}

void SafetyActuator::power_off() {
    orders_->zero_all(ZeroOrder::First); // thrusters first, whatever the action decided
    // The power-off line once the zeros are on the wire (the bus worker's thread).
    bus_.when_idle([this] { lines_.assert_power_off(); });
}

void SafetyActuator::after_zeros(Completion done, Result r) {
    bus_.when_idle([done = std::move(done), r = std::move(r)] { done(r); });
}

} // namespace caracara
