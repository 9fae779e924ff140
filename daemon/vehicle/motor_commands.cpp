#include "daemon/vehicle/motor_commands.hpp"

#include "daemon/loop/log.hpp"

#include <string>

namespace caracara {

MotorCommands::MotorCommands(const DaemonConfig& config, const SafetyMachine& safety, CommandAcceptance& acceptance,
                             SafetyActuator& actuator, VehicleEvents& events)
    : config_(config),
      safety_(safety),
      acceptance_(acceptance),
      actuator_(actuator),
      events_(events),
      demand_(config.control.budget_policy, *find_profile(config, config.control.profile)) {}

void MotorCommands::hand_down() {
    MotorValues orders{};
    for (size_t i = 0; i < kMotorCount; ++i)
        orders[i] = order_value(i);
    actuator_.hand_down(orders);
}

Result MotorCommands::take(const MotorVerdict& v) {
    if (!v.ok())
        return v.result;
    // A stream re-sending the same command changes nothing worth announcing.
    const bool changed = demand_.take(v.wanted, v.budget, v.mix_saturated);
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
    return take(acceptance_.thrust(values, demand_, client));
}

Result MotorCommands::set_motion(const AxisDemand& demand, std::string_view client) {
    return take(acceptance_.motion(demand, demand_, client));
}

Result MotorCommands::drive(const MotorValues& values, std::string_view client, const Result& range) {
    return take(acceptance_.motors(values, demand_, client, range));
}

void MotorCommands::exclude(const std::array<bool, kMotorCount>& excluded) {
    const bool changed = demand_.set_excluded(excluded);
    hand_down();
    events_.changed(changed ? kChangeMotors : 0u);
}

Result MotorCommands::surface(const AxisDemand& ascent) { return take(acceptance_.ascent(ascent, demand_)); }

} // namespace caracara
