#include "daemon/thruster_bus.hpp"

#include "daemon/log.hpp"

#include <algorithm>
#include <array>

namespace caracara {

namespace {
std::vector<std::unique_ptr<ThrusterDriver>> make_drivers(I2cDev& i2c, MuxTracker& mux, const DaemonConfig& config) {
    std::vector<std::unique_ptr<ThrusterDriver>> out;
    for (const auto& tc : config.thrusters)
        out.push_back(std::make_unique<ThrusterDriver>(i2c, mux, tc));
    return out;
}
} // namespace

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
      thrusters_(make_drivers(i2c_, mux_, config)),
      worker_(thrusters_),
      ordered_(config.thrusters.size(), 0),
      faults_(config.thrusters.size()),
      lockup_(static_cast<uint32_t>(kMotorCount)),
      failed_in_row_(config.thrusters.size(), 0),
      unreachable_(config.thrusters.size(), false) {}

std::string ThrusterBus::start(sd_event* event, int64_t priority, std::function<void(const BusJob&)> done) {
    on_done_ = std::move(done);
    return worker_.start(event, priority, [this](const BusJobDone& d) { this->done(d); });
}

void ThrusterBus::send_order(std::size_t i, int32_t value) {
    ordered_[i] = value;
    worker_.submit({BusJobKind::Order, static_cast<uint32_t>(i), value});
}

void ThrusterBus::zero_all(ZeroOrder where) {
    std::array<BusJob, kMotorCount> zeros{};
    const std::size_t n = std::min(thrusters_.size(), zeros.size());
    for (std::size_t i = 0; i < n; ++i) {
        ordered_[i] = 0;
        zeros[i] = {BusJobKind::Order, static_cast<uint32_t>(i), 0};
    }
    // While recovering, the adapter is closed or about to be: the zeros go out when it is
    // back (BusRecovery::finish), not as failures that would hold the bus clear up.
    if (recovering_)
        return;
    if (where == ZeroOrder::First)
        worker_.submit_first(std::span<const BusJob>(zeros).first(n));
    else
        for (std::size_t i = 0; i < n; ++i)
            worker_.submit(zeros[i], false); // behind what is queued, not instead of it
}

void ThrusterBus::read_status(std::size_t i) {
    worker_.submit({BusJobKind::Status, static_cast<uint32_t>(i), 0});
}

void ThrusterBus::when_idle(std::function<void()> fn) {
    if (worker_.idle()) {
        fn();
        return;
    }
    when_idle_.push_back(std::move(fn));
}

void ThrusterBus::done(const BusJobDone& d) {
    if (!d.skipped) {
        note(d.error);
        track_reach(d.job.index, d.error);
    }
    if (d.job.kind == BusJobKind::Status && d.error == IoError::None)
        report_faults(d.job.index);
    if (worker_.idle() && !when_idle_.empty()) {
        auto fns = std::move(when_idle_);
        when_idle_.clear();
        for (auto& fn : fns)
            fn();
    }
    if (on_done_)
        on_done_(d.job);
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
        worker_.drop_queued(); // the adapter is about to close; what is on the wire finishes
    else
        lockup_.reset();
}

void ThrusterBus::track_reach(std::size_t i, IoError e) {
    if (e == IoError::None || e == IoError::BadReply) {
        failed_in_row_[i] = 0;
        if (unreachable_[i]) {
            unreachable_[i] = false;
            log_notice("thruster %zu answers again", i);
        }
        return;
    }
    // A closed adapter (recovery) or a lost bus is the bus's failure, not this thruster's.
    if (recovering_ || tm_.state != BusState::Ok || unreachable_[i] || ++failed_in_row_[i] < kUnreachableAfter)
        return;
    unreachable_[i] = true;
    if (gate_)
        gate_->device_lost(unreachable_reason(i));
}

std::string ThrusterBus::unreachable_reason(std::size_t i) const {
    return "thruster " + std::to_string(i) + " unreachable (" + std::to_string(kUnreachableAfter) +
           " transfers in a row failed, last " + std::string(io_error_name(thruster(i).last_error())) + ")";
}

void ThrusterBus::set_gate(CommandGate* gate) {
    gate_ = gate;
    if (const auto i = first_unreachable(); i && gate_)
        gate_->device_lost(unreachable_reason(*i));
}

std::optional<std::size_t> ThrusterBus::first_unreachable() const {
    for (std::size_t i = 0; i < unreachable_.size(); ++i)
        if (unreachable_[i])
            return i;
    return std::nullopt;
}

bool ThrusterBus::any_online() const {
    for (std::size_t i = 0; i < thrusters_.size(); ++i)
        if (thruster(i).online())
            return true;
    return false;
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
            if (tm_.state == BusState::Lost)
                log_notice("I2C bus %s is back; the vehicle stays killed until ClearKill", device_.c_str());
            tm_.state = BusState::Ok;
            events_.changed(kChangeState | kChangeBus);
        }
        return;
    }
    if (locked && listener_)
        listener_->bus_locked_up(lockup_.reason(tm_.last_error));
}

} // namespace caracara
