#include "daemon/vehicle/vehicle_condition.hpp"

#include "core/clock.hpp"
#include "drivers/platform/io_error.hpp"

#include <string>

namespace caracara {

Result VehicleCondition::state_error() const {
    // Nothing moves while the thrusters cannot be reached: no order could get there, and each
    // thruster keeps whatever it was last told. Killed too, but this is what to fix first.
    if (bus_.monitor().telemetry().state == BusState::Lost && safety_.state() != SafetyState::PoweredOff)
        return {Status::BusLost, "the I2C bus to the thrusters is lost (" + bus_.monitor().telemetry().last_recovery_error +
                                     "); the vehicle stays killed until it is back and ClearKill is called"};
    switch (safety_.state()) {
    case SafetyState::Ready: return {};
    case SafetyState::Arming: return {Status::Arming, "the vehicle is arming; commands are accepted when it is ready"};
    case SafetyState::Killed:
        return {Status::Killed, "the vehicle is killed (" + std::string(kill_source_name()) + "); call ClearKill first"};
    case SafetyState::PoweredOff: return {Status::PoweredOff, "the vehicle is powered off"};
    }
    return {Status::Hardware, "unknown state"};
}

Result VehicleCondition::clear_kill_refusal() const {
    if (bus_.monitor().telemetry().state == BusState::Lost && safety_.state() == SafetyState::Killed)
        return {Status::BusLost, "the I2C bus to the thrusters is not back yet; the kill stays"};
    if (const auto i = bus_.health().first_unreachable(); i && safety_.state() == SafetyState::Killed)
        return {Status::ThrusterUnreachable,
                "thruster " + std::to_string(*i) + " does not answer (last " +
                    std::string(io_error_name(bus_.thruster(*i).last_error())) + "); the kill stays"};
    if (lines_.kill_output_missing() && safety_.state() == SafetyState::Killed)
        return {Status::Hardware, "the kill output line is gone (asked for again once a second); the kill stays"};
    if (safety_.state() == SafetyState::Killed)
        return failsafes_.clear_kill_refusal();
    return {};
}

Result VehicleCondition::power_off_refusal(std::string_view confirmation) {
    if (confirmation == kPowerOffConfirmation)
        return {};
    return {Status::ConfirmationRequired,
            std::string("power-off is irreversible: pass the confirmation string \"") + kPowerOffConfirmation + "\""};
}

std::string_view VehicleCondition::state_name() const {
    // A vehicle that could run but reaches none of its thrusters is in fault, whatever it was asked.
    const SafetyState s = safety_.state();
    if ((s == SafetyState::Ready || s == SafetyState::Arming) && bus_.monitor().telemetry().state == BusState::Lost)
        return "fault";
    return caracara::state_name(s);
}

std::string_view VehicleCondition::kill_source_name() const {
    if (safety_.state() != SafetyState::Killed)
        return "";
    return caracara::kill_source_name(safety_.kill_record().source);
}

int64_t VehicleCondition::command_age_ms() const {
    const uint64_t last = safety_.commands().last_command_at();
    if (last == 0)
        return -1;
    return static_cast<int64_t>((monotonic_ns() - last) / 1'000'000ull);
}

} // namespace caracara
