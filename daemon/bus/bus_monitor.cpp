#include "daemon/bus/bus_monitor.hpp"

#include "core/motor.hpp"
#include "daemon/loop/log.hpp"

namespace caracara {

BusMonitor::BusMonitor(std::string device, VehicleEvents& events)
    : events_(events), device_(std::move(device)), lockup_(static_cast<uint32_t>(kMotorCount)) {}

void BusMonitor::set_recovering(bool r) {
    recovering_ = r;
    if (!r)
        lockup_.reset();
}

void BusMonitor::note(IoError e) {
    ++tm_.transactions;
    if (recovering_)
        return; // the bus is closed on purpose; failures now say nothing new
    const LockupDetector::Transfer t = lockup_transfer(e);
    if (t != LockupDetector::Transfer::Ok) {
        ++tm_.errors;
        tm_.last_error = std::string(io_error_name(e));
    }
    const bool locked = lockup_.note(t);
    if (t == LockupDetector::Transfer::Ok || t == LockupDetector::Transfer::BadReply) {
        // A bad reply still crossed the bus: the thruster is at fault, not the wire.
        if (tm_.state != BusState::Ok) {
            const bool was_lost = tm_.state == BusState::Lost;
            if (was_lost)
                log_notice("I2C bus %s is back; the vehicle stays killed until ClearKill", device_.c_str());
            tm_.state = BusState::Ok;
            if (was_lost && listener_)
                listener_->bus_back();
            events_.changed(kChangeState | kChangeBus);
        }
        return;
    }
    if (locked && listener_)
        listener_->bus_locked_up(lockup_.reason(tm_.last_error));
}

} // namespace caracara
