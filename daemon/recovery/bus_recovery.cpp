#include "daemon/recovery/bus_recovery.hpp"

#include "core/clock.hpp"
#include "daemon/loop/log.hpp"
#include "drivers/platform/io_error.hpp"

namespace caracara {

namespace {
constexpr uint64_t kNodePollNs = 5'000'000;
constexpr uint64_t kIdlePollNs = 1'000'000;
constexpr uint64_t kReopenNs = 1'000'000'000;
} // namespace

BusRecovery::BusRecovery(sd_event* event, const DaemonConfig& config, DeviceIo& io, GpioBackend& gpio,
                         ThrusterBus& bus, ControlLoop& loop, FailsafeGate& failsafes, VehicleEvents& events)
    : event_(event),
      config_(config),
      bus_(bus),
      steps_(config, io, gpio, bus),
      loop_(loop),
      events_(events),
      loss_(event, config.control, bus, failsafes, events),
      policy_(config.recovery.attempts, config.recovery.backoff_ms) {}

void BusRecovery::bus_locked_up(const std::string& reason) {
    BusTelemetry& tm = bus_.monitor().telemetry();
    if (bus_.monitor().recovering() || tm.state == BusState::Lost)
        return;
    if (!config_.recovery.enabled) {
        // Nothing to clear the bus with: report it and keep trying the transfers each tick.
        log_error("I2C bus %s lost (%s); recovery is not configured: reopening the adapter once a second",
                  bus_.monitor().device().c_str(), reason.c_str());
        events_.bus_lost(reason);
        loss_.declare(reason);
        // An adapter that went away (unbound, a restarted simulator) is only found again by
        // opening its node anew; the transfers of each cycle then tell whether it is back.
        phase_ = Phase::Reopening;
        schedule(kReopenNs);
        return;
    }
    bus_.set_recovering(true);
    policy_.begin(monotonic_ns());
    tm.state = BusState::Recovering;
    tm.last_recovery_error = reason;
    log_warning("I2C bus %s locked up (%s): recovering", bus_.monitor().device().c_str(), reason.c_str());
    events_.bus_lost(reason);
    events_.changed(kChangeBus);
    // From the event loop, not from inside the transfer that noticed it.
    schedule(0);
    loss_.watch();
}

void BusRecovery::reopen() {
    if (bus_.monitor().telemetry().state != BusState::Lost) {
        phase_ = Phase::Idle; // a transfer got through: the bus is back
        return;
    }
    if (!bus_.worker().idle()) {
        schedule(kIdlePollNs); // not under a transfer on the worker's thread
        return;
    }
    steps_.reopen_adapter();
    schedule(kReopenNs);
}

void BusRecovery::schedule(uint64_t delay_ns) {
    const uint64_t at_us = (monotonic_ns() + delay_ns) / 1000;
    if (!timer_) {
        sd_event_source* s = nullptr;
        if (sd_event_add_time(event_, &s, CLOCK_MONOTONIC, at_us, 1, on_timer, this) < 0) {
            log_error("cannot schedule the bus recovery");
            return;
        }
        timer_.reset(s);
    }
    sd_event_source_set_time(timer_.get(), at_us);
    sd_event_source_set_enabled(timer_.get(), SD_EVENT_ONESHOT);
}

int BusRecovery::on_timer(sd_event_source*, uint64_t, void* userdata) {
    auto* self = static_cast<BusRecovery*>(userdata);
    switch (self->phase_) {
    case Phase::WaitingNode: self->wait_node(); break;
    case Phase::Verifying: self->verify(); break;
    case Phase::Reopening: self->reopen(); break;
    case Phase::Idle:
    case Phase::Backoff: self->attempt(); break;
    }
    return 0;
}

void BusRecovery::attempt() {
    const RecoverySettings& rc = config_.recovery;
    if (!bus_.worker().idle()) {
        // A transfer is still on the wire (bounded by the adapter's timeout): the descriptor
        // cannot be closed under it.
        schedule(kIdlePollNs);
        return;
    }
    policy_.next_attempt();
    phase_ = Phase::Idle;
    const BusClearResult bc = steps_.clear();
    last_pulses_ = bc.pulses;
    if (!bc.ok()) {
        failed(bc.message);
        return;
    }
    node_deadline_ns_ = monotonic_ns() + ms_to_ns(rc.device_wait_ms);
    phase_ = Phase::WaitingNode;
    wait_node();
}

void BusRecovery::wait_node() {
    const int r = steps_.open_node();
    if (r == 0) {
        finish();
        return;
    }
    if (monotonic_ns() >= node_deadline_ns_) {
        failed("the I2C device node did not come back: " + errno_name(-r));
        return;
    }
    schedule(kNodePollNs);
}

void BusRecovery::finish() {
    phase_ = Phase::Idle;
    // The current orders go out at once (zeros while the vehicle may not drive). Still flagged
    // as recovering, so these transfers decide the outcome (verify) instead of starting a new
    // recovery.
    loop_.resend_orders();
    phase_ = Phase::Verifying;
    schedule(kIdlePollNs);
}

void BusRecovery::verify() {
    if (!bus_.worker().idle()) {
        schedule(kIdlePollNs); // the orders are still on the wire (the worker's thread)
        return;
    }
    phase_ = Phase::Idle;
    if (!bus_.any_online()) {
        // The lines were cleared and the node is back, but nothing gets through: not recovered.
        bus_.close();
        failed("no thruster answers after the bus clear");
        return;
    }
    bus_.set_recovering(false);
    loss_.recovered();
    BusTelemetry& tm = bus_.monitor().telemetry();
    const bool was_lost = tm.state == BusState::Lost;
    tm.state = BusState::Ok;
    ++tm.recoveries;
    tm.last_pulses = last_pulses_;
    tm.last_recovery_ms = policy_.elapsed_ms(monotonic_ns());
    log_notice("I2C bus recovered after %u pulse(s), %.1f ms, attempt %u; orders re-sent", last_pulses_,
               tm.last_recovery_ms, policy_.attempt());
    events_.bus_restored(last_pulses_, tm.last_recovery_ms);
    events_.changed(kChangeBus | (was_lost ? kChangeState : 0u));
}

void BusRecovery::failed(const std::string& why) {
    BusTelemetry& tm = bus_.monitor().telemetry();
    ++tm.recovery_failures;
    tm.last_recovery_error = why;
    phase_ = Phase::Backoff;
    log_error("I2C bus recovery attempt %u failed: %s", policy_.attempt(), why.c_str());
    const RecoveryPolicy::Failure f = policy_.failed();
    if (f.lost)
        loss_.declare("recovery failed: " + why);
    events_.changed(kChangeBus);
    schedule(f.retry_in_ns);
}

} // namespace caracara
