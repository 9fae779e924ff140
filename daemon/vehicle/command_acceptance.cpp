#include "daemon/vehicle/command_acceptance.hpp"

#include "core/clock.hpp"
#include "core/status_of.hpp"

#include <algorithm>
#include <string>

namespace caracara {

namespace {

MotorVerdict refused(Result r) {
    MotorVerdict v;
    v.result = std::move(r);
    return v;
}

} // namespace

Result CommandAcceptance::state(std::string_view client) const {
    if (surfacing_ && client != kFailsafeClient)
        return {Status::Surfacing, "a failsafe is surfacing the vehicle; Kill stops it"};
    return condition_.state_error();
}

MotorVerdict CommandAcceptance::thrust(std::span<const int32_t> values, const MotorDemand& demand,
                                       std::string_view client) {
    if (Result r = state(client); !r.ok())
        return refused(std::move(r));
    if (values.size() != kMotorCount)
        return refused({Status::InvalidLength, "SetThrust needs exactly 8 motor values, got " + std::to_string(values.size())});
    MotorValues m{};
    std::copy(values.begin(), values.end(), m.begin());
    return within_range_and_budget(m, false, demand, client);
}

MotorVerdict CommandAcceptance::motion(const AxisDemand& axes, const MotorDemand& demand, std::string_view client) {
    if (Result r = state(client); !r.ok())
        return refused(std::move(r));
    const MixResult mr = mix(axes, mixing_);
    if (!mr.ok())
        return refused({status_of(mr.error), mr.message});
    return within_range_and_budget(mr.motors, mr.saturated, demand, client);
}

MotorVerdict CommandAcceptance::motors(const MotorValues& values, const MotorDemand& demand, std::string_view client,
                                       const Result& range) {
    if (Result r = state(client); !r.ok())
        return refused(std::move(r));
    if (!range.ok())
        return refused(range);
    return within_range_and_budget(values, false, demand, client);
}

MotorVerdict CommandAcceptance::ascent(const AxisDemand& axes, const MotorDemand& demand) {
    MotorVerdict v = motion(axes, demand, kFailsafeClient);
    surfacing_ = v.ok();
    return v;
}

Result CommandAcceptance::accept_command(std::string_view client, const Result& range) {
    if (Result r = state(client); !r.ok())
        return r;
    if (!range.ok())
        return range;
    return take(client);
}

MotorVerdict CommandAcceptance::within_range_and_budget(const MotorValues& wanted, bool mix_saturated,
                                                        const MotorDemand& demand, std::string_view client) {
    for (size_t i = 0; i < kMotorCount; ++i)
        if (wanted[i] < -kMotorMax || wanted[i] > kMotorMax)
            return refused({Status::OutOfRange, "motor " + std::to_string(i) + ": " + std::to_string(wanted[i]) +
                                                    " is outside -8850..8850"});
    MotorVerdict v;
    v.budget = demand.evaluate(wanted);
    if (!v.budget.ok())
        return refused({status_of(v.budget.error), v.budget.message});
    if (Result r = take(client); !r.ok())
        return refused(std::move(r));
    v.wanted = wanted;
    v.mix_saturated = mix_saturated;
    return v;
}

Result CommandAcceptance::take(std::string_view client) {
    const std::string previous = safety_.commands().client();
    if (!safety_.accept_command(monotonic_ns(), client).ok())
        return condition_.state_error();
    deadline_.arm(safety_.next_deadline());
    if (previous != safety_.commands().client())
        events_.changed(kChangeController);
    pilots_.tell_failsafes(); // a pilot again: pilot-lost ends
    return {};
}

} // namespace caracara
