#include "daemon/failsafe/failsafe_ascent.hpp"

#include "daemon/loop/log.hpp"

namespace caracara {

void FailsafeAscent::begin(std::string reason, uint64_t now) {
    // Nothing to drive while arming or killed: a surface then ends as it would, killed.
    reason_ = std::move(reason);
    if (!vehicle_.readings().may_drive() || !vehicle_.motors().surface(AxisDemand{0, 0, settings_.heave, 0, 0, 0}).ok()) {
        vehicle_.kill(KillSource::Failsafe, reason_ + ": the vehicle could not drive the ascent");
        return;
    }
    until_ = now + uint64_t(settings_.duration_ms) * 1'000'000ull;
    log_warning("SURFACING (%s): heave %g for %u ms, then kill", reason_.c_str(), settings_.heave,
                settings_.duration_ms);
    events_.changed(kChangeState);
}

void FailsafeAscent::keep(uint64_t now) {
    if (until_ == 0)
        return;
    if (!vehicle_.readings().surfacing()) { // a Kill, the kill switch or another fault ended it
        log_notice("surfacing ended by a kill (%s)", std::string(vehicle_.readings().kill_source_name()).c_str());
        until_ = 0;
        events_.changed(kChangeState);
        return;
    }
    if (now >= until_) {
        until_ = 0;
        vehicle_.kill(KillSource::Failsafe, reason_ + ": ascent done");
        return;
    }
    // Again, or the command timeout would stop the ascent.
    vehicle_.motors().surface(AxisDemand{0, 0, settings_.heave, 0, 0, 0});
}

} // namespace caracara
