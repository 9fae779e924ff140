#include "daemon/controller.hpp"

#include "devices/i2c_bus_clear.hpp"
#include "daemon/log.hpp"
#include "core/packet.hpp"

#include <algorithm>
#include <cmath>
#include <poll.h>
#include <systemd/sd-daemon.h>

namespace caracara {

namespace {
constexpr uint64_t kTelemetryPeriodNs = 200'000'000; // 5 Hz of PropertiesChanged
constexpr uint32_t kBackstopRateHz = 50;                // the tick at loop rate 0
constexpr const char* kPowerOffConfirmation = "power-off";
// A locked bus shows as several bus-level errors in a row (timeouts, EIO, a vanished adapter),
// or as every thruster failing at once; one absent thruster is neither.
constexpr uint32_t kLockupBusErrors = 3;
constexpr uint32_t kLockupFailures = 2 * kMotorCount;
constexpr uint64_t kNodePollNs = 5'000'000;
constexpr uint64_t kBackgroundRetryNs = 5'000'000'000ull;

GpioLineSpec line_spec(const GpioLineSettings& s) {
    GpioLineSpec spec;
    spec.chip = s.chip;
    spec.name = s.name;
    spec.offset = s.offset;
    spec.active_low = s.active_low;
    return spec;
}

Status teensy_status(teensy::TeensyError e) {
    using E = teensy::TeensyError;
    switch (e) {
    case E::None: return Status::Ok;
    case E::SpeedOutOfRange:
    case E::DutyOutOfRange:
    case E::ServoIdOutOfRange:
    case E::ServoAngleOutOfRange:
    case E::SensorIdOutOfRange:
    case E::AxisOutOfRange:
    case E::LedValueOutOfRange: return Status::OutOfRange;
    case E::AngleNotFinite: return Status::InvalidValue;
    case E::Busy:
    case E::BusyExhausted: return Status::Busy;
    case E::ConfirmTimeout: return Status::Timeout;
    case E::LinkError:
    case E::BadAnswer:
    case E::Io:
    case E::ConfirmAckFailed: return Status::LinkError;
    }
    return Status::LinkError;
}

Result teensy_result(teensy::TeensyError e, std::string_view what) {
    if (e == teensy::TeensyError::None)
        return {};
    return {teensy_status(e), std::string(what) + ": " + std::string(teensy::teensy_error_name(e))};
}
} // namespace

Controller::Controller(sd_event* event, DeviceIo& io, GpioBackend& gpio, DaemonConfig config)
    : event_(event),
      io_(io),
      gpio_(gpio),
      config_(std::move(config)),
      i2c_(io_, config_.i2c.device),
      spi_(io_, config_.spi.device, config_.spi.spi),
      teensy_link_(spi_, config_.spi.teensy),
      safety_(safety_config(config_), false, now()) {
    for (const auto& tc : config_.thrusters)
        thrusters_.push_back(std::make_unique<ThrusterDriver>(i2c_, mux_, tc));
    teensy_tm_.distances.assign(static_cast<size_t>(config_.spi.teensy.limits.distance_sensor_count), 0);
    teensy_tm_.servos.assign(static_cast<size_t>(config_.spi.teensy.limits.servo_count), 0);
}

Controller::~Controller() { shutdown(); }

uint64_t Controller::now() const { return monotonic_ns(); }

std::string Controller::start() {
    if (int r = i2c_.open(); r < 0)
        return "cannot open I2C bus " + config_.i2c.device + ": " + errno_name(-r);
    // Zero before anything else: a previous instance may have died with orders standing.
    zero_now();
    if (std::string e = open_gpio(); !e.empty())
        return e;
    if (int r = spi_.open(); r < 0) {
        log_warning("Teensy SPI %s unavailable (%s); continuing without it", config_.spi.device.c_str(),
                    errno_name(-r).c_str());
    } else {
        teensy_tm_.online = true;
    }

    sd_event_source* s = nullptr;
    int r = sd_event_add_defer(event_, &s, on_work, this);
    if (r < 0)
        return "sd_event_add_defer: " + errno_name(-r);
    work_source_.reset(s);
    sd_event_source_set_priority(s, kWorkPriority);
    sd_event_source_set_enabled(s, SD_EVENT_OFF);

    // The work steps aside after each burst of orders and at the end of a cycle, so that what
    // is below it (the announcements) runs even when the bus is busy all the time.
    r = sd_event_add_defer(event_, &s, on_resume, this);
    if (r < 0)
        return "sd_event_add_defer: " + errno_name(-r);
    resume_source_.reset(s);
    sd_event_source_set_priority(s, kAnnouncePriority + 1);
    sd_event_source_set_enabled(s, SD_EVENT_OFF);

    // At loop rate 0 the tick is a backstop: cycles follow each other at once, but while the
    // bus is being recovered there is nothing to clock out and the tick paces them.
    uint64_t now_us = 0;
    sd_event_now(event_, CLOCK_MONOTONIC, &now_us);
    // Accuracy 1 us: 0 would mean sd-event's default of 250 ms and a 4 Hz "50 Hz" loop.
    r = sd_event_add_time(event_, &s, CLOCK_MONOTONIC, now_us, 1, on_tick, this);
    if (r < 0)
        return "sd_event_add_time: " + errno_name(-r);
    tick_source_.reset(s);
    sd_event_source_set_enabled(s, SD_EVENT_ON);
    started_ = true;
    last_cycle_ns_ = now();
    cycle();
    return {};
}

void Controller::shutdown() {
    if (!started_)
        return;
    started_ = false;
    tick_source_.reset();
    work_source_.reset();
    resume_source_.reset();
    turn_source_.reset();
    recovery_timer_.reset();
    kill_switch_source_.reset();
    zero_now();
    if (turn_done_)
        finish_turn({Status::Hardware, "the daemon is shutting down"});
    i2c_.close();
    spi_.close();
}

int Controller::on_tick(sd_event_source* s, uint64_t usec, void* userdata) {
    auto* self = static_cast<Controller*>(userdata);
    const uint32_t hz = self->config_.control.loop_rate_hz;
    const uint64_t period = 1'000'000ull / (hz ? hz : kBackstopRateHz);
    // Fixed-rate schedule; after a stall skip ahead instead of bursting to catch up.
    uint64_t next = usec + period;
    uint64_t now_us = 0;
    sd_event_now(self->event_, CLOCK_MONOTONIC, &now_us);
    if (next <= now_us)
        next = now_us + period;
    sd_event_source_set_time(s, next);
    self->cycle();
    return 0;
}

bool Controller::input_pending() const {
    // Something for a higher-priority source: a D-Bus message (read already, or on the
    // socket) or a kill switch edge. One poll() instead of a full event-loop iteration.
    if (!input_)
        return true;
    if (input_->queued())
        return true;
    pollfd fds[2]{{input_->fd(), POLLIN, 0}, {-1, POLLIN, 0}};
    if (kill_switch_)
        fds[1].fd = kill_switch_->event_fd();
    return ::poll(fds, 2, 0) != 0;
}

int Controller::on_work(sd_event_source*, void* userdata) {
    auto* self = static_cast<Controller*>(userdata);
    auto step_aside = [self] {
        sd_event_source_set_enabled(self->work_source_.get(), SD_EVENT_OFF);
        sd_event_source_set_enabled(self->resume_source_.get(), SD_EVENT_ONESHOT);
    };
    // Transactions back to back while nothing else waits; the check between them keeps a
    // Kill or a command at most one transaction away.
    for (int n = 0; n < 32; ++n) {
        const Work w = self->work_one();
        if (w == Work::None) {
            self->in_cycle_ = false;
            self->last_cycle_ns_ = self->now();
            const bool flat_out = self->config_.control.loop_rate_hz == 0 && !self->recovering_;
            if (flat_out || self->cycle_overrun_)
                step_aside(); // on_resume starts the next cycle
            else
                sd_event_source_set_enabled(self->work_source_.get(), SD_EVENT_OFF);
            return 0;
        }
        if (w == Work::Order && !self->any_order_due()) {
            step_aside(); // the orders are out: announce, then the rest
            return 0;
        }
        if (self->input_pending())
            return 0;
    }
    return 0;
}

int Controller::on_resume(sd_event_source*, void* userdata) {
    auto* self = static_cast<Controller*>(userdata);
    if (!self->in_cycle_ && (self->config_.control.loop_rate_hz == 0 || self->cycle_overrun_)) {
        self->cycle_overrun_ = false;
        self->cycle(); // as fast as the bus allows
    } else {
        self->schedule_work();
    }
    return 0;
}

void Controller::schedule_work() {
    // While the work has stepped aside (on_resume pending; sd-event turns a one-shot source off
    // before dispatching it), on_resume takes it up again right after the announcements: a
    // tick or a command in between must not put it back in front of them.
    int resume_pending = SD_EVENT_OFF;
    if (resume_source_)
        sd_event_source_get_enabled(resume_source_.get(), &resume_pending);
    if (work_source_ && resume_pending == SD_EVENT_OFF)
        sd_event_source_set_enabled(work_source_.get(), SD_EVENT_ON);
}

void Controller::cycle() {
    const uint64_t t = now();
    poll_kill_switch(); // a backstop for a lost edge event
    handle(safety_.tick(t));
    if (in_cycle_) {
        // The bus did not finish the last cycle in one period: the next one starts as soon as
        // it is done, as at loop rate 0. Refreshing the orders now instead would put them in
        // front of that cycle's status reads at every tick, and they would never be read.
        cycle_overrun_ = true;
        publish_telemetry_if_due();
        return;
    }
    ++cycles_;
    in_cycle_ = true;
    refresh_orders();
    status_due_ = config_.control.status_reads_per_tick;
    teensy_due_ = spi_.is_open();
    publish_telemetry_if_due();
}

void Controller::refresh_orders() {
    // A burst still going out (a new command's orders) already refreshes every thruster:
    // those sent are fresh, the rest are due. Restarting it would only delay the last ones.
    if (!any_order_due())
        order_due_.fill(true);
    schedule_work();
}

bool Controller::any_order_due() const {
    return std::any_of(order_due_.begin(), order_due_.end(), [](bool d) { return d; });
}

bool Controller::send_next_due_order() {
    for (size_t i = 0; i < thrusters_.size() && !recovering_; ++i) {
        if (order_due_[i]) {
            order_due_[i] = false;
            send_order(i);
            return true;
        }
    }
    return false;
}

Controller::Work Controller::work_one() {
    if (send_next_due_order())
        return Work::Order;
    if (status_due_ > 0 && !recovering_) {
        --status_due_;
        const size_t i = status_next_;
        status_next_ = (status_next_ + 1) % thrusters_.size();
        note_bus_result(thrusters_[i]->read_status());
        return Work::Other;
    }
    if (teensy_due_) {
        teensy_due_ = false;
        poll_teensy();
        return Work::Other;
    }
    return Work::None;
}

void Controller::send_order(size_t i) {
    const int32_t v = safety_.may_drive() ? applied_[i] : 0;
    ordered_[i] = v;
    note_bus_result(thrusters_[i]->send_order(v));
}

void Controller::send_due_orders() {
    while (send_next_due_order()) {
    }
}

void Controller::zero_now() {
    // Back to back, without returning to the event loop: nothing may come between a kill
    // and the zero orders. Failures are counted; the next tick retries.
    for (size_t i = 0; i < thrusters_.size(); ++i) {
        order_due_[i] = false;
        ordered_[i] = 0;
        note_bus_result(thrusters_[i]->send_order(0));
    }
}

void Controller::note_bus_result(IoError e) {
    ++bus_tm_.transactions;
    if (recovering_)
        return; // the bus is closed on purpose; failures now say nothing new
    if (e == IoError::None || e == IoError::BadReply) {
        // A bad reply still crossed the bus: the thruster is at fault, not the wire.
        consecutive_bus_errors_ = 0;
        consecutive_failures_ = 0;
        if (e == IoError::BadReply) {
            ++bus_tm_.errors;
            bus_tm_.last_error = std::string(io_error_name(e));
        }
        if (bus_tm_.state != "ok") {
            bus_tm_.state = "ok";
            notify(kChangeState | kChangeBus);
        }
        return;
    }
    ++bus_tm_.errors;
    bus_tm_.last_error = std::string(io_error_name(e));
    ++consecutive_failures_;
    consecutive_bus_errors_ = bus_level_error(e) ? consecutive_bus_errors_ + 1 : 0;
    if (consecutive_bus_errors_ >= kLockupBusErrors || consecutive_failures_ >= kLockupFailures)
        start_recovery(consecutive_bus_errors_ >= kLockupBusErrors
                           ? std::to_string(consecutive_bus_errors_) + " bus errors in a row, last " + bus_tm_.last_error
                           : "every thruster failing, last " + bus_tm_.last_error);
}

bool Controller::bus_level_error(IoError e) const {
    return e == IoError::Timeout || e == IoError::ClockStretch || e == IoError::Arbitration || e == IoError::NoDevice;
}

// --- I2C bus lockup recovery ------------------------------------------------------------

void Controller::start_recovery(const std::string& reason) {
    if (recovering_ || bus_tm_.state == "lost")
        return;
    if (!config_.recovery.enabled) {
        // Nothing to clear the bus with: report it and keep trying the transfers each tick.
        bus_tm_.state = "lost";
        bus_tm_.last_recovery_error = reason;
        log_error("I2C bus %s lost (%s); recovery is not configured", config_.i2c.device.c_str(), reason.c_str());
        if (observer_)
            observer_->bus_lost(reason);
        notify(kChangeState | kChangeBus);
        return;
    }
    recovering_ = true;
    attempt_ = 0;
    recovery_started_ns_ = now();
    bus_tm_.state = "recovering";
    bus_tm_.last_recovery_error = reason;
    order_due_.fill(false);
    status_due_ = 0;
    log_warning("I2C bus %s locked up (%s): recovering", config_.i2c.device.c_str(), reason.c_str());
    if (observer_)
        observer_->bus_lost(reason);
    notify(kChangeBus);
    // From the event loop, not from inside the transfer that noticed it.
    schedule_recovery(0);
}

void Controller::schedule_recovery(uint64_t delay_ns) {
    const uint64_t at_us = (now() + delay_ns) / 1000;
    if (!recovery_timer_) {
        sd_event_source* s = nullptr;
        if (sd_event_add_time(event_, &s, CLOCK_MONOTONIC, at_us, 1, on_recovery_timer, this) < 0) {
            log_error("cannot schedule the bus recovery");
            return;
        }
        recovery_timer_.reset(s);
    }
    sd_event_source_set_time(recovery_timer_.get(), at_us);
    sd_event_source_set_enabled(recovery_timer_.get(), SD_EVENT_ONESHOT);
}

int Controller::on_recovery_timer(sd_event_source*, uint64_t, void* userdata) {
    auto* self = static_cast<Controller*>(userdata);
    if (self->recovery_phase_ == RecoveryPhase::WaitingNode)
        self->recovery_wait_node();
    else
        self->recovery_attempt();
    return 0;
}

void Controller::recovery_attempt() {
    const RecoverySettings& rc = config_.recovery;
    ++attempt_;
    recovery_phase_ = RecoveryPhase::Idle;
    i2c_.close(); // before unbinding: the driver cannot go while the node is open
    mux_.invalidate();
    const bool rebind = !rc.driver_id.empty();
    if (rebind && release_node_holders_)
        release_node_holders_(); // nor while anyone else has it open: unbind would never return
    if (rebind) {
        if (int r = sysfs_write(io_, rc.unbind_path, rc.driver_id); r < 0 && r != -ENODEV)
            log_warning("unbinding %s via %s: %s", rc.driver_id.c_str(), rc.unbind_path.c_str(), errno_name(-r).c_str());
    }
    BusClearResult bc = i2c_bus_clear(gpio_, line_spec(*config_.gpio.scl), line_spec(*config_.gpio.sda));
    last_pulses_ = bc.pulses;
    if (rebind) {
        // Even after a failed clear: the node must come back for the next attempt.
        if (int r = sysfs_write(io_, rc.bind_path, rc.driver_id); r < 0 && r != -EBUSY)
            log_warning("binding %s via %s: %s", rc.driver_id.c_str(), rc.bind_path.c_str(), errno_name(-r).c_str());
    }
    if (!bc.ok()) {
        recovery_failed(bc.message);
        return;
    }
    log_info("bus clear: SDA released after %u clock pulses, STOP sent", bc.pulses);
    node_deadline_ns_ = now() + ms_to_ns(rc.device_wait_ms);
    recovery_phase_ = RecoveryPhase::WaitingNode;
    recovery_wait_node();
}

void Controller::recovery_wait_node() {
    int r = i2c_.open();
    if (r == 0) {
        if (reopen_node_holders_)
            reopen_node_holders_();
        recovery_finish();
        return;
    }
    if (now() >= node_deadline_ns_) {
        recovery_failed("the I2C device node did not come back: " + errno_name(-r));
        return;
    }
    schedule_recovery(kNodePollNs);
}

void Controller::recovery_finish() {
    recovery_phase_ = RecoveryPhase::Idle;
    // The current orders go out at once, a pending kill first: zeros while the vehicle may not
    // drive. Still flagged as recovering, so these transfers decide the outcome below instead
    // of starting a new recovery.
    if (safety_.may_drive())
        for (size_t i = 0; i < thrusters_.size(); ++i)
            send_order(i);
    else
        zero_now();
    bool answered = false;
    for (const auto& t : thrusters_)
        answered = answered || t->online();
    if (!answered) {
        // The lines were cleared and the node is back, but nothing gets through: not recovered.
        i2c_.close();
        recovery_failed("no thruster answers after the bus clear");
        return;
    }
    recovering_ = false;
    consecutive_bus_errors_ = 0;
    consecutive_failures_ = 0;
    const bool was_lost = bus_tm_.state == "lost";
    bus_tm_.state = "ok";
    ++bus_tm_.recoveries;
    bus_tm_.last_pulses = last_pulses_;
    bus_tm_.last_recovery_ms = static_cast<double>(now() - recovery_started_ns_) / 1e6;
    log_notice("I2C bus recovered after %u pulse(s), %.1f ms, attempt %u; orders re-sent", last_pulses_,
               bus_tm_.last_recovery_ms, attempt_);
    if (observer_)
        observer_->bus_restored(last_pulses_, bus_tm_.last_recovery_ms);
    notify(kChangeBus | (was_lost ? kChangeState : 0u));
}

void Controller::recovery_failed(const std::string& why) {
    const RecoverySettings& rc = config_.recovery;
    ++bus_tm_.recovery_failures;
    bus_tm_.last_recovery_error = why;
    recovery_phase_ = RecoveryPhase::Backoff;
    log_error("I2C bus recovery attempt %u failed: %s", attempt_, why.c_str());
    if (attempt_ == rc.attempts) {
        bus_tm_.state = "lost";
        kill(KillSource::Fault, "I2C bus recovery failed: " + why);
        notify(kChangeState);
    }
    notify(kChangeBus);
    // Bounded attempts with exponential backoff, then slow retries in the background.
    uint64_t delay = kBackgroundRetryNs;
    if (attempt_ < rc.attempts)
        delay = std::min<uint64_t>(ms_to_ns(rc.backoff_ms) << std::min<uint32_t>(attempt_ - 1, 16), kBackgroundRetryNs);
    schedule_recovery(delay);
}

// --- GPIO lines ---------------------------------------------------------------------------

std::string Controller::open_gpio() {
    const GpioSettings& g = config_.gpio;
    std::string err;
    if (g.kill_output) {
        kill_out_ = gpio_.request(line_spec(*g.kill_output), GpioMode::Output, safety_.kill_output_asserted() ? 1 : 0, err);
        if (!kill_out_)
            return "gpio.kill_output: " + err;
    }
    if (g.power_off_output) {
        power_off_out_ = gpio_.request(line_spec(*g.power_off_output), GpioMode::Output, 0, err);
        if (!power_off_out_)
            return "gpio.power_off_output: " + err;
    }
    if (g.kill_switch) {
        kill_switch_ = gpio_.request(line_spec(*g.kill_switch), GpioMode::InputEdges, 0, err);
        if (!kill_switch_)
            return "gpio.kill_switch: " + err;
        sd_event_source* s = nullptr;
        // Above D-Bus and the bus work: the switch is the operator's hand on the vehicle.
        if (int fd = kill_switch_->event_fd(); fd >= 0) {
            if (int r = sd_event_add_io(event_, &s, fd, EPOLLIN, on_kill_switch, this); r < 0)
                return "gpio.kill_switch: cannot watch edges: " + errno_name(-r);
            kill_switch_source_.reset(s);
            sd_event_source_set_priority(s, SD_EVENT_PRIORITY_IMPORTANT);
        }
        poll_kill_switch();
    }
    return {};
}

int Controller::on_kill_switch(sd_event_source*, int, uint32_t, void* userdata) {
    auto* self = static_cast<Controller*>(userdata);
    if (self->kill_switch_->drain_events() < 0)
        log_error("kill switch events: the line went away");
    self->poll_kill_switch();
    return 0;
}

void Controller::poll_kill_switch() {
    if (!kill_switch_)
        return;
    const int v = kill_switch_->get();
    if (v < 0)
        return;
    const bool set = v == 1;
    if (set == safety_.kill_switch_set())
        return;
    const bool was_killed = safety_.state() == SafetyState::Killed;
    handle(safety_.switch_changed(set, now()));
    if (set && !was_killed)
        log_warning("KILLED by the kill switch");
    else if (!set)
        log_notice("kill switch released; ClearKill re-arms the vehicle");
    if (set && !was_killed)
        stop_teensy_motion();
    if (set && turn_done_)
        finish_turn({Status::Killed, "the kill switch was set during the turn"});
}

void Controller::update_outputs() {
    if (kill_out_)
        kill_out_->set(safety_.kill_output_asserted() ? 1 : 0);
}

void Controller::handle(const SafetyAction& a) {
    uint32_t changes = 0;
    if (a.clear_commands) {
        requested_.fill(0);
        applied_.fill(0);
        limit_ = 0;
        saturated_ = false;
        changes |= kChangeMotors | kChangeController;
    }
    if (a.zero_outputs)
        zero_now();
    if (a.state_changed) {
        changes |= kChangeState;
        update_outputs(); // the kill output follows the state, after the zero orders
    }
    if (a.command_stale)
        log_info("command stream silent for %llu ms: thrusters to zero",
                 static_cast<unsigned long long>(config_.control.command_timeout_ms));
    notify(changes);
}

void Controller::notify(uint32_t changes) {
    if (changes & (kChangeState | kChangeBus)) {
        // What `systemctl status caracarad` shows on its Status: line.
        std::string ks(kill_source_name());
        sd_notifyf(0, "STATUS=%s%s%s; I2C bus %s; %zu thrusters", std::string(state_name()).c_str(),
                   ks.empty() ? "" : " by ", ks.c_str(), bus_tm_.state.c_str(), thrusters_.size());
    }
    if (changes && observer_)
        observer_->vehicle_changed(changes);
}

Result Controller::state_error() const {
    switch (safety_.state()) {
    case SafetyState::Ready: return {};
    case SafetyState::Arming: return {Status::Arming, "the vehicle is arming; commands are accepted when it is ready"};
    case SafetyState::Killed:
        return {Status::Killed, "the vehicle is killed (" + std::string(kill_source_name()) + "); call ClearKill first"};
    case SafetyState::PoweredOff: return {Status::PoweredOff, "the vehicle is powered off"};
    }
    return {Status::Hardware, "unknown state"};
}

Result Controller::accept_motors(const MotorValues& wanted, bool mix_saturated, std::string_view client) {
    BudgetResult b = apply_budget(wanted, config_.control.budget_policy);
    if (b.error == BudgetError::OutOfRange)
        return {Status::OutOfRange, b.message};
    if (b.error == BudgetError::OverBudget)
        return {Status::OverBudget, b.message};
    if (Result r = state_error(); !r.ok())
        return r;
    const std::string previous = safety_.commanding_client();
    SafetyAction a = safety_.accept_command(now(), client);
    if (!a.ok())
        return state_error();
    const int32_t limit = b.running ? b.limit : 0;
    const bool saturated = b.saturated || mix_saturated;
    // A stream re-sending the same command changes nothing worth announcing.
    const bool changed = requested_ != wanted || applied_ != b.motors || limit_ != limit || saturated_ != saturated;
    // The changed orders go out now, one transaction per loop iteration, not at the next tick;
    // an unchanged one is already on the wire and refreshed by the tick.
    bool any_due = false;
    for (size_t i = 0; i < kMotorCount; ++i)
        if (applied_[i] != b.motors[i] || ordered_[i] != b.motors[i]) {
            order_due_[i] = true;
            any_due = true;
        }
    requested_ = wanted;
    applied_ = b.motors;
    limit_ = limit;
    saturated_ = saturated;
    if (any_due)
        schedule_work();
    notify((changed ? kChangeMotors : 0u) | (previous != safety_.commanding_client() ? kChangeController : 0u));
    return {};
}

Result Controller::set_thrust(std::span<const int32_t> values, std::string_view client) {
    if (values.size() != kMotorCount)
        return {Status::InvalidLength, "SetThrust needs exactly 8 motor values, got " + std::to_string(values.size())};
    MotorValues m{};
    for (size_t i = 0; i < kMotorCount; ++i) {
        if (values[i] < -kMotorMax || values[i] > kMotorMax)
            return {Status::OutOfRange, "motor " + std::to_string(i) + ": " + std::to_string(values[i]) +
                                            " is outside -8850..8850"};
        m[i] = values[i];
    }
    return accept_motors(m, false, client);
}

Result Controller::set_motion(const AxisDemand& demand, std::string_view client) {
    MixResult mr = mix(demand, config_.mixing);
    if (mr.error == MixError::NotFinite)
        return {Status::InvalidValue, mr.message};
    if (mr.error != MixError::None)
        return {Status::OutOfRange, mr.message};
    return accept_motors(mr.motors, mr.saturated, client);
}

Result Controller::apply_packet(std::span<const int32_t> words, std::string_view client) {
    PacketResult pr = decode_packet(words);
    switch (pr.error) {
    case PacketError::None: break;
    case PacketError::WrongLength: return {Status::InvalidLength, pr.message};
    case PacketError::MotorOutOfRange:
    case PacketError::ColorOutOfRange: return {Status::OutOfRange, pr.message};
    case PacketError::BadPowerOffState: return {Status::InvalidValue, pr.message};
    }
    const Packet& p = pr.packet;
    if (safety_.state() == SafetyState::PoweredOff)
        return state_error();
    if (p.kill) {
        // The seed: a non-zero killState stops the motors until a zero is sent.
        kill(KillSource::Packet, "packet killState=" + std::to_string(p.kill_state));
        set_leds(p.red, p.green, p.blue);
        return {};
    }
    if (p.power_off) {
        Result r = power_off(kPowerOffConfirmation);
        return r;
    }
    if (safety_.state() == SafetyState::Killed) {
        if (safety_.kill_source() != KillSource::Packet)
            return state_error();
        // killState 0 is the packet's "all clear": it clears a packet kill (arming follows).
        SafetyAction a = safety_.clear_kill(now());
        if (!a.ok())
            return {a.error == SafetyError::KillSwitchSet ? Status::KillSwitchSet : Status::Killed, a.message};
        handle(a);
        set_leds(p.red, p.green, p.blue);
        return {};
    }
    Result r = accept_motors(p.motors, false, client);
    if (!r.ok())
        return r;
    if (leds_ != std::array<uint8_t, 3>{p.red, p.green, p.blue})
        set_leds(p.red, p.green, p.blue);
    return {};
}

Result Controller::kill(KillSource source, std::string_view reason) {
    const bool was_killed = safety_.state() == SafetyState::Killed;
    SafetyAction a = safety_.kill(source, now(), reason);
    handle(a);
    if (!was_killed && safety_.state() == SafetyState::Killed)
        log_warning("KILLED by %s%s%s", std::string(kill_source_name()).c_str(), reason.empty() ? "" : ": ",
                    std::string(reason).c_str());
    stop_teensy_motion();
    if (turn_done_)
        finish_turn({Status::Killed, "the vehicle was killed during the turn"});
    return {};
}

void Controller::stop_teensy_motion() {
    // Kill stops every motor, the Teensy's drive too: Stop halts the wheels and ends a turn.
    if (!spi_.is_open())
        return;
    if (auto e = teensy_link_.stop(0); e != teensy::TeensyError::None)
        log_error("Teensy Stop on kill failed: %s", std::string(teensy::teensy_error_name(e)).c_str());
}

Result Controller::clear_kill() {
    SafetyAction a = safety_.clear_kill(now());
    switch (a.error) {
    case SafetyError::None: break;
    case SafetyError::NotKilled: return {Status::NotKilled, a.message};
    case SafetyError::KillSwitchSet: return {Status::KillSwitchSet, a.message};
    case SafetyError::PoweredOff: return {Status::PoweredOff, a.message};
    case SafetyError::NotReady: return {Status::Arming, a.message};
    }
    handle(a);
    log_notice("kill cleared; arming for %u ms", config_.control.arming_delay_ms);
    return {};
}

Result Controller::power_off(std::string_view confirmation) {
    if (confirmation != kPowerOffConfirmation)
        return {Status::ConfirmationRequired,
                std::string("power-off is irreversible: pass the confirmation string \"") + kPowerOffConfirmation + "\""};
    SafetyAction a = safety_.power_off(now());
    if (a.error == SafetyError::PoweredOff)
        return {Status::PoweredOff, a.message};
    handle(a);
    zero_now(); // thrusters first, whatever handle() decided
    if (power_off_out_)
        power_off_out_->set(1);
    log_warning("POWER-OFF confirmed: thrusters zeroed%s", power_off_out_ ? ", power-off line asserted" : "");
    stop_teensy_motion();
    if (turn_done_)
        finish_turn({Status::PoweredOff, "the vehicle was powered off during the turn"});
    return {};
}

Result Controller::set_leds(int red, int green, int blue) {
    if (safety_.state() == SafetyState::PoweredOff)
        return state_error();
    for (int v : {red, green, blue})
        if (v < 0 || v > 255)
            return {Status::OutOfRange, "LED values are 0..255"};
    if (!spi_.is_open())
        return {Status::LinkError, "the Teensy is not connected"};
    if (Result r = teensy_result(teensy_link_.set_leds(red, green, blue), "Set LEDs"); !r.ok())
        return r;
    leds_ = {static_cast<uint8_t>(red), static_cast<uint8_t>(green), static_cast<uint8_t>(blue)};
    notify(kChangeLeds);
    return {};
}

void Controller::client_left(std::string_view unique_name) {
    if (unique_name.empty() || unique_name != safety_.commanding_client())
        return;
    log_notice("controlling client %s left the bus: thrusters to zero", std::string(unique_name).c_str());
    // A command it had accepted reaches the wire before the zero: a one-shot `busctl call`
    // moves the thrusters for a moment, the same whether or not its disconnect happens to
    // arrive before the loop sent the orders.
    send_due_orders();
    SafetyAction a = safety_.client_left(unique_name, now());
    handle(a); // clear_commands announces Controller with the motors
}

std::string_view Controller::state_name() const {
    // A vehicle that could run but reaches none of its thrusters is in fault, whatever it was asked.
    const SafetyState s = safety_.state();
    if ((s == SafetyState::Ready || s == SafetyState::Arming) && bus_tm_.state == "lost")
        return "fault";
    return caracara::state_name(s);
}

std::string_view Controller::kill_source_name() const {
    if (safety_.state() != SafetyState::Killed)
        return "";
    return caracara::kill_source_name(safety_.kill_source());
}

int64_t Controller::command_age_ms() const {
    const uint64_t last = safety_.last_command_at();
    if (last == 0)
        return -1;
    return static_cast<int64_t>((now() - last) / 1'000'000ull);
}

bool Controller::healthy(uint64_t now_ns) const {
    const uint64_t period = config_.control.loop_rate_hz ? 1'000'000'000ull / config_.control.loop_rate_hz : 0;
    const uint64_t allowed = std::max<uint64_t>(1'000'000'000ull, 5 * period);
    // A bus under recovery is not an unhealthy loop: restarting the daemon would not help it.
    return started_ && now_ns - last_cycle_ns_ <= allowed;
}

void Controller::publish_telemetry_if_due() {
    const uint64_t t = now();
    if (t - last_telemetry_ns_ < kTelemetryPeriodNs)
        return;
    last_telemetry_ns_ = t;
    if (observer_)
        observer_->telemetry();
}

// --- Teensy ---------------------------------------------------------------------------

void Controller::poll_teensy() {
    // One frame per cycle: the three orientation axes, then one distance sensor, in turn.
    const unsigned sensors = static_cast<unsigned>(teensy_tm_.distances.size());
    const unsigned slots = 3 + (sensors ? 1 : 0);
    const unsigned slot = teensy_poll_index_ % slots;
    ++teensy_poll_index_;
    bool ok = false;
    if (slot < 3) {
        auto r = teensy_link_.get_orientation(static_cast<int>(slot));
        ok = r.ok();
        if (ok)
            teensy_tm_.orientation[slot] = r.value;
    } else {
        const unsigned sensor = (teensy_poll_index_ / slots) % sensors;
        auto r = teensy_link_.get_distance(static_cast<int>(sensor));
        ok = r.ok();
        if (ok)
            teensy_tm_.distances[sensor] = r.value;
    }
    teensy_tm_.online = ok;
}

Result Controller::teensy_set_speed(int left, int right) {
    // Drive motors are motors: only a ready vehicle moves them (stopping is always allowed).
    if (Result r = state_error(); !r.ok() && (left != 0 || right != 0))
        return r;
    return teensy_result(teensy_link_.set_speed(left, right), "Set Speed");
}

Result Controller::teensy_stop(int duty) { return teensy_result(teensy_link_.stop(duty), "Stop"); }

Result Controller::teensy_servo(int id, int degrees) {
    if (safety_.state() == SafetyState::PoweredOff)
        return state_error();
    Result r = teensy_result(teensy_link_.servo(id, degrees), "Servo");
    if (r.ok())
        teensy_tm_.servos[static_cast<size_t>(id)] = static_cast<uint8_t>(degrees);
    return r;
}

Result Controller::teensy_distance(int sensor, uint16_t& mm) {
    auto r = teensy_link_.get_distance(sensor);
    if (!r.ok())
        return teensy_result(r.error, "Get distance");
    mm = r.value;
    if (sensor >= 0 && static_cast<size_t>(sensor) < teensy_tm_.distances.size())
        teensy_tm_.distances[static_cast<size_t>(sensor)] = mm;
    return {};
}

Result Controller::teensy_turn(double radians, bool absolute, std::function<void(const Result&)> done) {
    if (Result r = state_error(); !r.ok())
        return r;
    if (turn_done_)
        return {Status::Busy, "a turn is already running"};
    if (!std::isfinite(radians))
        return {Status::InvalidValue, "the angle must be a finite number of radians"};
    auto e = absolute ? teensy_link_.turn_to(radians) : teensy_link_.turn(radians);
    if (Result r = teensy_result(e, absolute ? "Turn to" : "Turn"); !r.ok())
        return r;
    turn_done_ = std::move(done);
    teensy_tm_.turning = true;
    handshake_ = teensy::ConfirmHandshake();
    handshake_.start(now());
    sd_event_source* s = nullptr;
    uint64_t now_us = 0;
    sd_event_now(event_, CLOCK_MONOTONIC, &now_us);
    if (sd_event_add_time(event_, &s, CLOCK_MONOTONIC, now_us, 1, on_turn_step, this) < 0) {
        finish_turn({Status::Hardware, "cannot schedule the confirmation handshake"});
        return {};
    }
    turn_source_.reset(s);
    return {};
}

int Controller::on_turn_step(sd_event_source*, uint64_t, void* userdata) {
    static_cast<Controller*>(userdata)->turn_step();
    return 0;
}

void Controller::turn_step() {
    // Drive the handshake without blocking: send what it asks for, then sleep until it
    // wants the next poll.
    for (;;) {
        const uint64_t t = now();
        auto step = handshake_.next(t);
        switch (step.action) {
        case teensy::ConfirmHandshake::Action::Send: {
            auto reply = teensy_link_.execute(step.frame);
            teensy::TeensyResult<uint8_t> res;
            if (!reply.ok())
                res.error = reply.error;
            else
                res = teensy::decode_confirm(reply.value);
            handshake_.on_result(res, now());
            continue;
        }
        case teensy::ConfirmHandshake::Action::Wait:
            sd_event_source_set_time(turn_source_.get(), step.at_ns / 1000);
            sd_event_source_set_enabled(turn_source_.get(), SD_EVENT_ONESHOT);
            return;
        case teensy::ConfirmHandshake::Action::Done:
            finish_turn({});
            return;
        case teensy::ConfirmHandshake::Action::Failed:
        case teensy::ConfirmHandshake::Action::Idle:
            finish_turn(teensy_result(step.error == teensy::TeensyError::None ? teensy::TeensyError::LinkError : step.error,
                                      "turn confirmation"));
            return;
        }
    }
}

void Controller::finish_turn(const Result& r) {
    teensy_tm_.turning = false;
    auto done = std::move(turn_done_);
    turn_done_ = nullptr;
    turn_source_.reset();
    if (done)
        done(r);
}

} // namespace caracara
