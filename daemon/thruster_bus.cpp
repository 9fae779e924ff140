#include "daemon/thruster_bus.hpp"

#include "daemon/log.hpp"

#include <algorithm>

namespace caracara {

std::string_view bus_state_name(BusState s) {
    switch (s) {
    case BusState::Ok: return "ok";
    case BusState::Recovering: return "recovering";
    case BusState::Lost: return "lost";
    }
    return "ok";
}

ThrusterBus::ThrusterBus(DeviceIo& io, const DaemonConfig& config, VehicleEvents& events)
    : events_(events),
      device_(config.i2c.device),
      i2c_(io, config.i2c.device, {config.i2c.timeout_ms, config.i2c.retries}),
      ordered_(config.thrusters.size(), 0),
      faults_(config.thrusters.size()),
      schedule_(config.thrusters.size()),
      lockup_(static_cast<uint32_t>(kMotorCount)) {
    for (const auto& tc : config.thrusters)
        thrusters_.push_back(std::make_unique<ThrusterDriver>(i2c_, mux_, tc));
}

void ThrusterBus::send_order(std::size_t i, int32_t value) {
    ordered_[i] = value;
    note(thrusters_[i]->send_order(value));
}

void ThrusterBus::zero_all() {
    schedule_.drop_orders();
    for (std::size_t i = 0; i < thrusters_.size(); ++i)
        send_order(i, 0);
}

void ThrusterBus::read_status(std::size_t i) {
    const IoError e = thrusters_[i]->read_status();
    note(e);
    if (e == IoError::None)
        report_faults(i);
}

void ThrusterBus::report_faults(std::size_t i) {
    const auto& st = thrusters_[i]->last_status();
    const FaultSet now = st ? st->faults : FaultSet{};
    if (now == faults_[i])
        return;
    for (Fault f : kAllFaults)
        if (now.has(f) != faults_[i].has(f))
            log_thruster_fault(i, fault_name(f), now.has(f));
    faults_[i] = now;
    events_.changed(kChangeFaults);
}

void ThrusterBus::set_recovering(bool r) {
    recovering_ = r;
    if (r)
        schedule_.drop_bus_work();
    else
        lockup_.reset();
}

bool ThrusterBus::any_online() const {
    return std::any_of(thrusters_.begin(), thrusters_.end(), [](const auto& t) { return t->online(); });
}

void ThrusterBus::note(IoError e) {
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
            tm_.state = BusState::Ok;
            events_.changed(kChangeState | kChangeBus);
        }
        return;
    }
    if (locked && listener_)
        listener_->bus_locked_up(lockup_.reason(tm_.last_error));
}

} // namespace caracara
