#include "core/lockup_detector.hpp"

namespace caracara {

bool LockupDetector::note(Transfer t) {
    if (t == Transfer::Ok || t == Transfer::BadReply) {
        reset();
        return false;
    }
    ++failures_;
    bus_errors_ = t == Transfer::BusError ? bus_errors_ + 1 : 0;
    return bus_errors_ >= kBusErrors || failures_ >= failure_limit_;
}

void LockupDetector::reset() {
    bus_errors_ = 0;
    failures_ = 0;
}

std::string LockupDetector::reason(const std::string& last_error) const {
    if (bus_errors_ >= kBusErrors)
        return std::to_string(bus_errors_) + " bus errors in a row, last " + last_error;
    return "every thruster failing, last " + last_error;
}

} // namespace caracara
