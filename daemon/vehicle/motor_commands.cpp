#include "daemon/vehicle/motor_commands.hpp"

#include "core/status_of.hpp"

#include "daemon/loop/log.hpp"

#include <string>

namespace caracara {

MotorCommands::MotorCommands(const DaemonConfig& config, const SafetyMachine& safety, CommandGate& gate,
                             SafetyActuator& actuator, VehicleEvents& events)
    : config_(config),
      safety_(safety),
      gate_(gate),
      actuator_(actuator),
      events_(events),
      demand_(config.control.budget_policy, *find_profile(config, config.control.profile)) {}

void MotorCommands::hand_down() {
    MotorValues orders{};
    for (size_t i = 0; i < kMotorCount; ++i)
        orders[i] = order_value(i);
    actuator_.hand_down(orders);
}

Result MotorCommands::accept(const MotorValues& wanted, bool mix_saturated, std::string_view client) {
    const BudgetResult b = demand_.evaluate(wanted);
    if (!b.ok())
        return {status_of(b.error), b.message};
    if (Result r = gate_.accept_command(client); !r.ok())
        return r;
    // A stream re-sending the same command changes nothing worth announcing.
    const bool changed = demand_.take(wanted, b, mix_saturated);
    hand_down();
    events_.changed(changed ? kChangeMotors : 0u);
    return {};
}

Result MotorCommands::set_profile(std::string_view name) {
    const ThrustProfile* p = find_profile(config_, name);
    if (!p)
        return {Status::UnknownProfile,
                "no thrust profile \"" + std::string(name) + "\"; known: " + profile_names(config_)};
    if (p == &demand_.profile())
        return {};
    log_notice("thrust profile %s (factor %g)", p->name.c_str(), p->factor);
    // The command standing now goes out under the new factor at once.
    const bool changed = demand_.set_profile(*p);
    hand_down();
    events_.changed(kChangeProfile | (changed ? kChangeMotors : 0u));
    return {};
}

Result MotorCommands::set_thrust(std::span<const int32_t> values, std::string_view client) {
    if (values.size() != kMotorCount)
        return {Status::InvalidLength, "SetThrust needs exactly 8 motor values, got " + std::to_string(values.size())};
    MotorValues m{};
    for (size_t i = 0; i < kMotorCount; ++i) {
        if (values[i] < -kMotorMax || values[i] > kMotorMax)
            return {Status::OutOfRange, "motor " + std::to_string(i) + ": " + std::to_string(values[i]) +
                                            " is outside -8850..8850"};
        m[i] = values[i];
    }
    return accept(m, false, client);
}

Result MotorCommands::set_motion(const AxisDemand& demand, std::string_view client) {
    MixResult mr = mix(demand, config_.mixing);
    if (mr.error != MixError::None)
        return {status_of(mr.error), mr.message};
    return accept(mr.motors, mr.saturated, client);
}

void MotorCommands::exclude(const std::array<bool, kMotorCount>& excluded) {
    const bool changed = demand_.set_excluded(excluded);
    hand_down();
    events_.changed(changed ? kChangeMotors : 0u);
}

Result MotorCommands::surface(const AxisDemand& ascent) {
    MixResult mr = mix(ascent, config_.mixing);
    if (mr.error != MixError::None)
        return {status_of(mr.error), mr.message};
    Result r = accept(mr.motors, mr.saturated, kFailsafeClient);
    surfacing_ = r.ok();
    return r;
}

} // namespace caracara
