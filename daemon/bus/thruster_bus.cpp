#include "daemon/bus/thruster_bus.hpp"

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

ThrusterBus::ThrusterBus(DeviceIo& io, const DaemonConfig& config, VehicleEvents& events)
    : monitor_(config.i2c.device, events),
      health_(config.thrusters.size(), events),
      i2c_(io, config.i2c.device, {config.i2c.timeout_ms, config.i2c.retries}),
      thrusters_(make_drivers(i2c_, mux_, config)),
      worker_(thrusters_),
      ordered_(config.thrusters.size(), 0) {}

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
    if (monitor_.recovering() && where == ZeroOrder::First && prober_)
        prober_->dropped();
    if (monitor_.recovering())
        return;
    if (where == ZeroOrder::First) {
        worker_.submit_first(std::span<const BusJob>(zeros).first(n));
        if (prober_)
            prober_->dropped(); // after the zeros: a kill ends a scan, its next step queued or not
    } else
        for (std::size_t i = 0; i < n; ++i)
            worker_.submit(zeros[i], false); // behind what is queued, not instead of it
}

void ThrusterBus::read_status(std::size_t i) {
    worker_.submit({BusJobKind::Status, static_cast<uint32_t>(i), 0});
}

void ThrusterBus::submit_probe(BusProber& prober, uint32_t step) {
    if (prober_ != &prober)
        worker_.set_prober(&prober); // before the job: submit() hands both to the thread
    prober_ = &prober;
    worker_.submit({BusJobKind::Probe, 0, static_cast<int32_t>(step)}, false);
    worker_.wake_when_done();
}

void ThrusterBus::when_idle(std::function<void()> fn) {
    if (worker_.idle()) {
        fn();
        return;
    }
    when_idle_.push_back(std::move(fn));
    update_wake_at_once();
}

void ThrusterBus::update_wake_at_once() {
    const bool at_once = !results_at_tick_ || !when_idle_.empty() || monitor_.recovering();
    if (at_once != wake_at_once_)
        worker_.set_wake_at_once(at_once);
    wake_at_once_ = at_once;
}

void ThrusterBus::done(const BusJobDone& d) {
    // A probe's NACK is an empty address, not a failing bus: the scan judges it.
    if (d.job.kind == BusJobKind::Probe && prober_)
        prober_->probed(d);
    else if (!d.skipped) {
        monitor_.note(d.error);
        health_.note(d.job.index, d.error, monitor_.healthy());
    }
    if (d.job.kind == BusJobKind::Status && d.error == IoError::None)
        health_.note_status(d.job.index, thruster(d.job.index).last_status());
    if (worker_.idle() && !when_idle_.empty()) {
        auto fns = std::move(when_idle_);
        when_idle_.clear();
        for (auto& fn : fns)
            fn();
        update_wake_at_once();
    }
    if (on_done_)
        on_done_(d.job);
}

void ThrusterBus::set_recovering(bool r) {
    monitor_.set_recovering(r);
    if (r) {
        worker_.drop_queued(); // the adapter is about to close; what is on the wire finishes
        if (prober_)
            prober_->dropped();
    }
    update_wake_at_once();
}

bool ThrusterBus::any_online() const {
    for (std::size_t i = 0; i < thrusters_.size(); ++i)
        if (thruster(i).online())
            return true;
    return false;
}

} // namespace caracara
