#include "daemon/failsafe/failsafe_clearance.hpp"

#include "daemon/failsafe/failsafe_report.hpp"
#include "daemon/loop/log.hpp"

#include <algorithm>
#include <string>

namespace caracara {

Result FailsafeClearance::refusal() const {
    // Bus lost, an unreachable thruster, the kill switch and the kill output are refused where
    // they arise, by name (BusLost, ThrusterUnreachable, KillSwitchSet, Hardware), and at once
    // when they end, not at this object's next reading; pilot lost ended with its kill (nothing
    // is left to lose); a lost power-off output does not keep the kill. The Teensy link is
    // refused here, by the failsafe that holds: no other error names it.
    std::vector<ActiveFailsafe> b = policy_.blocking();
    std::erase_if(b, [this](const ActiveFailsafe& f) {
        return (condition_is_fixed(f.condition) && f.condition != FailsafeCondition::TeensyLinkLost) ||
               (overriding_ && f.condition == *overriding_);
    });
    if (b.empty())
        return {};
    std::string m = "a failsafe holds: ";
    for (std::size_t i = 0; i < b.size(); ++i)
        m += (i ? ", " : "") + FailsafeReport::describe(b[i]);
    const auto fixed =
        std::find_if(b.begin(), b.end(), [](const ActiveFailsafe& f) { return condition_is_fixed(f.condition); });
    if (fixed != b.end())
        m += "; " + std::string(condition_name(fixed->condition)) + " is fixed at kill: ClearKill works once it clears";
    else
        m += "; ClearKillOverride(\"" + std::string(condition_name(b.front().condition)) +
             "\") clears the kill anyway";
    return {Status::FailsafeActive, m};
}

Result FailsafeClearance::clear_kill_override(std::string_view condition, std::string_view caller) {
    const auto c = condition_from_name(condition);
    if (!c)
        return {Status::InvalidValue, "no failsafe condition \"" + std::string(condition) + "\""};
    if (condition_is_fixed(*c))
        return {Status::FailsafeActive, std::string(condition) + " is fixed at kill: it cannot be overridden"};
    // ClearKill with the named condition's failsafes set aside (another that holds still
    // refuses); they are overridden only when it clears the kill: a refused call changes nothing.
    overriding_ = *c;
    Result r = vehicle_.clear_kill();
    overriding_.reset();
    if (!r.ok())
        return r;
    if (policy_.override_condition(*c)) {
        log_warning("FAILSAFE OVERRIDE: %s named %s in ClearKillOverride; it only warns until it clears",
                    std::string(caller).c_str(), std::string(condition).c_str());
        events_.changed(kChangeFailsafes);
    }
    return r;
}

} // namespace caracara
