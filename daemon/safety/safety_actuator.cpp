#include "daemon/safety/safety_actuator.hpp"

namespace caracara {

void SafetyActuator::carry_out(const SafetyAction& a, bool kill_output_asserted) {
    // A kill reaches the kill output first: it is one GPIO write, and the zero orders behind it
    // are bus transfers that a hung device can delay. Releasing it (arming) waits for the zeros.
    const bool assert_first = a.state_changed && kill_output_asserted;
    if (assert_first) {
        bus_.hold_orders();
        lines_.set_kill_output(true);
    }
    if (a.zero_outputs) {
        // A kill's zeros go before anything queued; a timeout's or a departed client's go
        // behind what that client had sent.
        orders_->zero_all(kill_output_asserted ? ZeroOrder::First : ZeroOrder::Behind);
        // The wheels are motors too. A kill or power-off stops them itself, and tells a
        // running turn why.
        if (!kill_output_asserted)
            teensy_.stop_if_moving();
    }
    if (a.state_changed && !assert_first)
        lines_.set_kill_output(kill_output_asserted);
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
