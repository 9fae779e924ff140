#include "daemon/vehicle/pilot_watch.hpp"

#include "core/clock.hpp"
#include "daemon/loop/log.hpp"

#include <string>

namespace caracara {

Result PilotWatch::accept_command(std::string_view client) {
    if (motors_.surfacing() && client != MotorCommands::kFailsafeClient)
        return {Status::Surfacing, "a failsafe is surfacing the vehicle; Kill stops it"};
    if (Result r = condition_.state_error(); !r.ok())
        return r;
    const std::string previous = safety_.commanding_client();
    if (!safety_.accept_command(monotonic_ns(), client).ok())
        return condition_.state_error();
    deadline_.arm(safety_.next_deadline());
    if (previous != safety_.commanding_client())
        events_.changed(kChangeController);
    return {};
}

void PilotWatch::client_left(std::string_view unique_name) {
    if (unique_name.empty())
        return;
    const bool was_lost = safety_.pilot_lost();
    if (unique_name == safety_.commanding_client()) {
        log_notice("controlling client %s left the bus: thrusters to zero", std::string(unique_name).c_str());
        // Its zeros go behind what it had sent (ZeroOrder::Behind).
        handle_(safety_.client_left(unique_name, monotonic_ns())); // announces Controller with the motors
    } else {
        safety_.client_left(unique_name, monotonic_ns()); // a pilot who no longer commands: no zeros
    }
    if (safety_.pilot_lost() && !was_lost) {
        log_warning("the last pilot (%s) left the bus: killed in %u ms (failsafe pilot-lost) unless a pilot commands",
                    std::string(unique_name).c_str(), failsafe_.rule(FailsafeCondition::PilotLost).persistence_ms);
        if (failsafes_)
            failsafes_->conditions_changed();
    }
}

} // namespace caracara
