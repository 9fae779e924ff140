#include "daemon/teensy_port.hpp"

#include "core/clock.hpp"
#include "daemon/log.hpp"
#include "drivers/platform/io_error.hpp"

#include <cerrno>

#include <cmath>
#include <memory>
#include <string>

namespace caracara {

namespace {

Result teensy_result(teensy::TeensyError e, std::string_view what) {
    if (e == teensy::TeensyError::None)
        return {};
    return {teensy::status_of(e), std::string(what) + ": " + std::string(teensy::teensy_error_name(e))};
}

} // namespace

namespace {
constexpr uint64_t kReopenUs = 1'000'000;
} // namespace

TeensyPort::TeensyPort(sd_event* event, DeviceIo& io, const SpiSettings& settings, CommandGate& gate,
                       VehicleEvents& events)
    : event_(event),
      gate_(gate),
      events_(events),
      spi_(io, settings.device, settings.spi),
      link_(spi_, settings.teensy),
      worker_(link_) {
    tm_.distances.assign(static_cast<size_t>(settings.teensy.limits.distance_sensor_count), 0);
    tm_.servos.assign(static_cast<size_t>(settings.teensy.limits.servo_count), 0);
}

int TeensyPort::open() {
    const int r = spi_.open();
    open_ = tm_.online = r >= 0;
    if (r < 0)
        schedule_reopen(); // a Teensy that comes later is picked up
    return r;
}

void TeensyPort::close() {
    if (turn_done_)
        finish_turn({Status::Hardware, "the daemon is shutting down"});
    worker_.stop(); // after the frame on the wire; what was queued (a Stop of the way out) still runs
    turn_source_.reset();
    reopen_timer_.reset();
    spi_.close();
    open_ = false;
}

void TeensyPort::schedule_reopen() {
    uint64_t now_us = 0;
    sd_event_now(event_, CLOCK_MONOTONIC, &now_us);
    if (!reopen_timer_) {
        sd_event_source* s = nullptr;
        if (sd_event_add_time(event_, &s, CLOCK_MONOTONIC, now_us + kReopenUs, 1000, on_reopen, this) < 0)
            return;
        reopen_timer_.reset(s);
    }
    sd_event_source_set_time(reopen_timer_.get(), now_us + kReopenUs);
    sd_event_source_set_enabled(reopen_timer_.get(), SD_EVENT_ONESHOT);
}

int TeensyPort::on_reopen(sd_event_source*, uint64_t, void* userdata) {
    auto* self = static_cast<TeensyPort*>(userdata);
    if (self->open_)
        return 0;
    // The node is opened on the worker: it may still be closing the old descriptor.
    auto r = std::make_shared<int>(0);
    self->worker_.submit([self, r] { *r = self->spi_.is_open() ? 0 : self->spi_.open(); },
                         [self, r] {
                             if (self->open_)
                                 return;
                             if (*r < 0) {
                                 self->schedule_reopen(); // quietly: one line when it went, one when it is back
                                 return;
                             }
                             log_notice("Teensy SPI %s is back", self->spi_.path().c_str());
                             self->open_ = true;
                             // Whatever the wheels were doing before, they stop now (as at every start).
                             self->stop_motion();
                             self->tm_.online = true;
                         });
    return 0;
}

void TeensyPort::link_lost() {
    if (!open_)
        return;
    log_error("Teensy SPI %s went away (%s): vehicle killed; asking for it again once a second",
              spi_.path().c_str(), errno_name(ENODEV).c_str());
    open_ = false;
    worker_.submit([this] { spi_.close(); }, nullptr);
    wheels_moving_ = false;
    tm_.online = false;
    gate_.device_lost("the Teensy's SPI device went away");
    schedule_reopen();
}

void TeensyPort::poll() {
    worker_.collect(); // the last poll's result, if it is in
    if (poll_out_ || !open_)
        return;
    const unsigned sensors = static_cast<unsigned>(tm_.distances.size());
    const unsigned slots = 3 + (sensors ? 1 : 0);
    poll_.slot = poll_index_ % slots;
    ++poll_index_;
    poll_.sensor = sensors ? (poll_index_ / slots) % sensors : 0;
    poll_out_ = true;
    // Captures `this` only: no allocation per poll.
    worker_.submit(
        [this] {
            if (poll_.slot < 3) {
                auto r = link_.get_orientation(static_cast<int>(poll_.slot));
                poll_.ok = r.ok();
                poll_.value = r.value;
            } else {
                auto r = link_.get_distance(static_cast<int>(poll_.sensor));
                poll_.ok = r.ok();
                poll_.value = r.value;
            }
            poll_.err = poll_.ok ? 0 : spi_.last_errno();
        },
        [this] { poll_done(); }, false);
}

void TeensyPort::poll_done() {
    poll_out_ = false;
    if (poll_.ok) {
        if (poll_.slot < 3)
            tm_.orientation[poll_.slot] = poll_.value;
        else
            tm_.distances[poll_.sensor] = static_cast<uint16_t>(poll_.value);
    }
    if (open_)
        tm_.online = poll_.ok;
    if (!poll_.ok && poll_.err == ENODEV)
        link_lost();
}

void TeensyPort::command(std::function<teensy::TeensyError()> frame, std::string what, Completion done) {
    auto e = std::make_shared<teensy::TeensyError>(teensy::TeensyError::None);
    auto err = std::make_shared<int>(0);
    worker_.submit(
        [this, frame = std::move(frame), e, err] {
            *e = frame();
            *err = *e == teensy::TeensyError::None ? 0 : spi_.last_errno();
        },
        [this, e, err, what = std::move(what), done = std::move(done)] {
            const Result r = teensy_result(*e, what);
            if (!r.ok() && *err == ENODEV)
                link_lost();
            if (done)
                done(r);
        });
}

void TeensyPort::stop_motion() {
    wheels_moving_ = false;
    if (!open_)
        return;
    command([this] { return link_.stop(0); }, "Stop", [](const Result& r) {
        if (!r.ok())
            log_error("Teensy Stop failed: %s", r.message.c_str());
    });
}

void TeensyPort::stop_if_moving() {
    if (!wheels_moving_ && !turn_done_)
        return;
    stop_motion();
    cancel_turn({Status::Timeout, "the turn was stopped: its command stream ended"});
}

void TeensyPort::cancel_turn(const Result& r) {
    if (turn_done_)
        finish_turn(r);
}

Result TeensyPort::set_leds(int red, int green, int blue, Completion done) {
    for (int v : {red, green, blue})
        if (v < 0 || v > 255)
            return {Status::OutOfRange, "LED values are 0..255"};
    if (!open_)
        return {Status::LinkError, "the Teensy is not connected"};
    const std::array<uint8_t, 3> want{static_cast<uint8_t>(red), static_cast<uint8_t>(green), static_cast<uint8_t>(blue)};
    // A packet stream repeats its LEDs at every packet: while the same values are on their way
    // (a slow Teensy), they are not queued again.
    if (!done && leds_out_ == want)
        return {};
    leds_out_ = want;
    command([this, red, green, blue] { return link_.set_leds(red, green, blue); }, "Set LEDs",
            [this, want, done = std::move(done)](const Result& r) {
                if (leds_out_ == want)
                    leds_out_.reset();
                if (r.ok()) {
                    leds_ = want;
                    events_.changed(kChangeLeds);
                }
                if (done)
                    done(r);
            });
    return {};
}

Result TeensyPort::set_speed(int left, int right, std::string_view client, Completion done) {
    // Drive motors are motors: only a ready vehicle moves them, as a command from the commanding
    // client under the command timeout (stopping is always allowed).
    const bool moving = left != 0 || right != 0;
    if (moving) {
        if (Result r = gate_.state_error(); !r.ok())
            return r;
        // Range first: a refused command changes nothing, not even who commands.
        if (auto e = teensy::encode_set_speed(left, right).error; e != teensy::TeensyError::None)
            return teensy_result(e, "Set Speed");
        if (Result r = gate_.accept_command(client); !r.ok())
            return r;
    }
    command([this, left, right] { return link_.set_speed(left, right); }, "Set Speed",
            [this, moving, done = std::move(done)](const Result& r) {
                if (r.ok())
                    wheels_moving_ = moving;
                if (done)
                    done(r);
            });
    return {};
}

Result TeensyPort::stop(int duty, Completion done) {
    command([this, duty] { return link_.stop(duty); }, "Stop", std::move(done));
    return {};
}

Result TeensyPort::servo(int id, int degrees, Completion done) {
    if (gate_.powered_off())
        return gate_.state_error();
    command([this, id, degrees] { return link_.servo(id, degrees); }, "Servo",
            [this, id, degrees, done = std::move(done)](const Result& r) {
                if (r.ok())
                    tm_.servos[static_cast<size_t>(id)] = static_cast<uint8_t>(degrees);
                if (done)
                    done(r);
            });
    return {};
}

Result TeensyPort::distance(int sensor, DistanceDone done) {
    auto mm = std::make_shared<uint16_t>(0);
    command(
        [this, sensor, mm] {
            auto r = link_.get_distance(sensor);
            *mm = r.value;
            return r.error;
        },
        "Get distance",
        [this, sensor, mm, done = std::move(done)](const Result& r) {
            if (r.ok() && sensor >= 0 && static_cast<size_t>(sensor) < tm_.distances.size())
                tm_.distances[static_cast<size_t>(sensor)] = *mm;
            if (done)
                done(r, *mm);
        });
    return {};
}

Result TeensyPort::turn(double radians, bool absolute, std::string_view client, Completion done) {
    if (Result r = gate_.state_error(); !r.ok())
        return r;
    if (turn_done_)
        return {Status::Busy, "a turn is already running"};
    if (!std::isfinite(radians))
        return {Status::InvalidValue, "the angle must be a finite number of radians"};
    if (Result r = gate_.accept_command(client); !r.ok())
        return r;
    turn_done_ = std::move(done);
    tm_.turning = true;
    const uint64_t id = ++turn_id_;
    command([this, radians, absolute] { return absolute ? link_.turn_to(radians) : link_.turn(radians); },
            absolute ? "Turn to" : "Turn", [this, id](const Result& r) {
                if (id != turn_id_ || !turn_done_)
                    return; // ended meanwhile (a kill)
                if (!r.ok()) {
                    finish_turn(r);
                    return;
                }
                handshake_ = teensy::ConfirmHandshake();
                handshake_.start(monotonic_ns());
                sd_event_source* s = nullptr;
                uint64_t now_us = 0;
                sd_event_now(event_, CLOCK_MONOTONIC, &now_us);
                if (sd_event_add_time(event_, &s, CLOCK_MONOTONIC, now_us, 1, on_turn_step, this) < 0) {
                    finish_turn({Status::Hardware, "cannot schedule the confirmation handshake"});
                    return;
                }
                turn_source_.reset(s);
            });
    return {};
}

int TeensyPort::on_turn_step(sd_event_source*, uint64_t, void* userdata) {
    static_cast<TeensyPort*>(userdata)->turn_step();
    return 0;
}

void TeensyPort::turn_step() {
    // Drive the handshake without blocking: the worker sends what it asks for, then the timer
    // sleeps until it wants the next poll.
    const uint64_t id = turn_id_;
    worker_.submit([this] { step_ = link_.advance(handshake_); },
                   [this, id] {
                       if (id != turn_id_ || !turn_done_)
                           return;
                       switch (step_.action) {
                       case teensy::ConfirmHandshake::Action::Wait:
                           sd_event_source_set_time(turn_source_.get(), step_.at_ns / 1000);
                           sd_event_source_set_enabled(turn_source_.get(), SD_EVENT_ONESHOT);
                           return;
                       case teensy::ConfirmHandshake::Action::Done:
                           finish_turn({});
                           return;
                       case teensy::ConfirmHandshake::Action::Send: // advance() never stops on a Send
                       case teensy::ConfirmHandshake::Action::Failed:
                       case teensy::ConfirmHandshake::Action::Idle:
                           finish_turn(teensy_result(step_.error == teensy::TeensyError::None ? teensy::TeensyError::LinkError
                                                                                              : step_.error,
                                                     "turn confirmation"));
                           return;
                       }
                   });
}

void TeensyPort::finish_turn(const Result& r) {
    ++turn_id_;
    tm_.turning = false;
    auto done = std::move(turn_done_);
    turn_done_ = nullptr;
    turn_source_.reset();
    if (done)
        done(r);
}

} // namespace caracara
