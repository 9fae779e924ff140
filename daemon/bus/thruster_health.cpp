#include "daemon/bus/thruster_health.hpp"

#include "daemon/loop/log.hpp"

namespace caracara {

ThrusterHealth::ThrusterHealth(std::size_t thrusters, VehicleEvents& events)
    : events_(events),
      faults_(thrusters),
      failed_in_row_(thrusters, 0),
      last_failure_(thrusters, IoError::None),
      unreachable_(thrusters, false) {}

void ThrusterHealth::note(std::size_t i, IoError e, bool bus_healthy) {
    if (e == IoError::None || e == IoError::BadReply) {
        failed_in_row_[i] = 0;
        if (unreachable_[i]) {
            unreachable_[i] = false;
            log_notice("thruster %zu answers again", i);
            if (failsafes_ && !first_unreachable())
                failsafes_->push(FailsafeCondition::ThrusterUnreachable, false, "every thruster answers");
        }
        return;
    }
    last_failure_[i] = e;
    if (!bus_healthy || unreachable_[i] || ++failed_in_row_[i] < kUnreachableAfter)
        return;
    unreachable_[i] = true;
    if (failsafes_)
        failsafes_->push(FailsafeCondition::ThrusterUnreachable, true, unreachable_reason(i));
}

void ThrusterHealth::note_status(std::size_t i, const std::optional<ThrusterStatus>& status) {
    const FaultSet now = status ? status->faults : FaultSet{};
    if (now == faults_[i])
        return;
    for (Fault f : kAllFaults)
        if (now.has(f) != faults_[i].has(f))
            log_thruster_fault(i, fault_name(f), now.has(f));
    faults_[i] = now;
    events_.changed(kChangeFaults);
}

std::string ThrusterHealth::unreachable_reason(std::size_t i) const {
    return "thruster " + std::to_string(i) + " unreachable (" + std::to_string(kUnreachableAfter) +
           " transfers in a row failed, last " + std::string(io_error_name(last_failure_[i])) + ")";
}

void ThrusterHealth::set_failsafes(FailsafeGate* failsafes) {
    failsafes_ = failsafes;
    if (const auto i = first_unreachable(); i && failsafes_)
        failsafes_->push(FailsafeCondition::ThrusterUnreachable, true, unreachable_reason(*i));
}

std::optional<std::size_t> ThrusterHealth::first_unreachable() const {
    for (std::size_t i = 0; i < unreachable_.size(); ++i)
        if (unreachable_[i])
            return i;
    return std::nullopt;
}

} // namespace caracara
