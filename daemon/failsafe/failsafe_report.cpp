#include "daemon/failsafe/failsafe_report.hpp"

#include "daemon/loop/log.hpp"

namespace caracara {

std::string FailsafeReport::describe(const ActiveFailsafe& f) {
    std::string s = std::string(condition_name(f.condition)) + " " + std::string(action_name(f.effective()));
    if (f.thruster >= 0)
        s += " thruster " + std::to_string(f.thruster);
    return s;
}

void FailsafeReport::tell(const FailsafeTransitions& ts) const {
    for (const FailsafeTransition& t : ts) {
        if (const uint32_t ms = settings_.rule(t.failsafe.condition).persistence_ms; t.raised && ms > 0)
            log_warning("FAILSAFE %s: the condition held for %u ms", describe(t.failsafe).c_str(), ms);
        else if (t.raised)
            log_warning("FAILSAFE %s", describe(t.failsafe).c_str());
        else
            log_notice("failsafe %s cleared: the condition is gone%s", describe(t.failsafe).c_str(),
                       condition_clearing(t.failsafe.condition) == FailsafeClearing::PowerCycle
                           ? " (the controller's power was cycled)"
                           : "");
        events_.failsafe(t.failsafe, t.raised);
    }
    if (!ts.empty())
        events_.changed(kChangeFailsafes);
}

} // namespace caracara
