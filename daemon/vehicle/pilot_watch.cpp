#include "daemon/vehicle/pilot_watch.hpp"

#include "core/clock.hpp"
#include "daemon/loop/log.hpp"

#include <string>

namespace caracara {

void PilotWatch::tell_failsafes() {
    if (safety_.pilot_lost() == told_lost_)
        return;
    told_lost_ = safety_.pilot_lost();
    failsafes_.push(FailsafeCondition::PilotLost, told_lost_,
                    told_lost_ ? "the last pilot left the bus" : "a pilot commands, or the pilots were forgotten");
}

void PilotWatch::client_left(std::string_view unique_name) {
    if (unique_name.empty())
        return;
    const bool was_lost = safety_.pilot_lost();
    if (unique_name == safety_.commands().client()) {
        log_notice("controlling client %s left the bus: thrusters to zero", std::string(unique_name).c_str());
        // Its zeros go behind what it had sent (ZeroOrder::Behind).
        handle_(safety_.client_left(unique_name, monotonic_ns())); // announces Controller with the motors
    } else {
        safety_.client_left(unique_name, monotonic_ns()); // a pilot who no longer commands: no zeros
    }
    if (safety_.pilot_lost() && !was_lost) {
        log_warning("the last pilot (%s) left the bus: killed in %u ms (failsafe pilot-lost) unless a pilot commands",
                    std::string(unique_name).c_str(), failsafe_.rule(FailsafeCondition::PilotLost).persistence_ms);
    }
    tell_failsafes();
}

} // namespace caracara
