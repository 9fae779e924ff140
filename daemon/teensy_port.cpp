#include "daemon/teensy_port.hpp"

#include "core/clock.hpp"
#include "daemon/log.hpp"
#include "drivers/platform/io_error.hpp"

#include <cerrno>

#include <cmath>
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
    : event_(event), gate_(gate), events_(events), spi_(io, settings.device, settings.spi), link_(spi_, settings.teensy) {
    tm_.distances.assign(static_cast<size_t>(settings.teensy.limits.distance_sensor_count), 0);
    tm_.servos.assign(static_cast<size_t>(settings.teensy.limits.servo_count), 0);
}

int TeensyPort::open() {
    const int r = spi_.open();
    tm_.online = r >= 0;
    if (r < 0)
        schedule_reopen(); // a Teensy that comes later is picked up
    return r;
}

void TeensyPort::close() {
    if (turn_done_)
        finish_turn({Status::Hardware, "the daemon is shutting down"});
    turn_source_.reset();
    reopen_timer_.reset();
    spi_.close();
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
    if (self->spi_.is_open())
        return 0;
    if (self->spi_.open() < 0) {
        self->schedule_reopen(); // quietly: one line when it went, one when it is back
        return 0;
    }
    log_notice("Teensy SPI %s is back", self->spi_.path().c_str());
    // Whatever the wheels were doing before, they stop now (as at every start).
    self->stop_motion();
    self->tm_.online = true;
    return 0;
}

void TeensyPort::link_lost() {
    log_error("Teensy SPI %s went away (%s): vehicle killed; asking for it again once a second",
              spi_.path().c_str(), errno_name(spi_.last_errno()).c_str());
    spi_.close();
    wheels_moving_ = false;
    tm_.online = false;
    gate_.device_lost("the Teensy's SPI device went away");
    schedule_reopen();
}

void TeensyPort::poll() {
    const unsigned sensors = static_cast<unsigned>(tm_.distances.size());
    const unsigned slots = 3 + (sensors ? 1 : 0);
    const unsigned slot = poll_index_ % slots;
    ++poll_index_;
    bool ok = false;
    if (slot < 3) {
        auto r = link_.get_orientation(static_cast<int>(slot));
        ok = r.ok();
        if (ok)
            tm_.orientation[slot] = r.value;
    } else {
        const unsigned sensor = (poll_index_ / slots) % sensors;
        auto r = link_.get_distance(static_cast<int>(sensor));
        ok = r.ok();
        if (ok)
            tm_.distances[sensor] = r.value;
    }
    tm_.online = ok;
    if (!ok && spi_.last_errno() == ENODEV)
        link_lost();
}

void TeensyPort::stop_motion() {
    wheels_moving_ = false;
    if (!spi_.is_open())
        return;
    if (auto e = link_.stop(0); e != teensy::TeensyError::None)
        log_error("Teensy Stop failed: %s", std::string(teensy::teensy_error_name(e)).c_str());
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

Result TeensyPort::set_leds(int red, int green, int blue) {
    for (int v : {red, green, blue})
        if (v < 0 || v > 255)
            return {Status::OutOfRange, "LED values are 0..255"};
    if (!spi_.is_open())
        return {Status::LinkError, "the Teensy is not connected"};
    if (Result r = teensy_result(link_.set_leds(red, green, blue), "Set LEDs"); !r.ok())
        return r;
    leds_ = {static_cast<uint8_t>(red), static_cast<uint8_t>(green), static_cast<uint8_t>(blue)};
    events_.changed(kChangeLeds);
    return {};
}

Result TeensyPort::set_speed(int left, int right, std::string_view client) {
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
    Result r = teensy_result(link_.set_speed(left, right), "Set Speed");
    if (r.ok())
        wheels_moving_ = moving;
    return r;
}

Result TeensyPort::stop(int duty) { return teensy_result(link_.stop(duty), "Stop"); }

Result TeensyPort::servo(int id, int degrees) {
    if (gate_.powered_off())
        return gate_.state_error();
    Result r = teensy_result(link_.servo(id, degrees), "Servo");
    if (r.ok())
        tm_.servos[static_cast<size_t>(id)] = static_cast<uint8_t>(degrees);
    return r;
}

Result TeensyPort::distance(int sensor, uint16_t& mm) {
    auto r = link_.get_distance(sensor);
    if (!r.ok())
        return teensy_result(r.error, "Get distance");
    mm = r.value;
    if (sensor >= 0 && static_cast<size_t>(sensor) < tm_.distances.size())
        tm_.distances[static_cast<size_t>(sensor)] = mm;
    return {};
}

Result TeensyPort::turn(double radians, bool absolute, std::string_view client,
                        Completion done) {
    if (Result r = gate_.state_error(); !r.ok())
        return r;
    if (turn_done_)
        return {Status::Busy, "a turn is already running"};
    if (!std::isfinite(radians))
        return {Status::InvalidValue, "the angle must be a finite number of radians"};
    if (Result r = gate_.accept_command(client); !r.ok())
        return r;
    auto e = absolute ? link_.turn_to(radians) : link_.turn(radians);
    if (Result r = teensy_result(e, absolute ? "Turn to" : "Turn"); !r.ok())
        return r;
    turn_done_ = std::move(done);
    tm_.turning = true;
    handshake_ = teensy::ConfirmHandshake();
    handshake_.start(monotonic_ns());
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

int TeensyPort::on_turn_step(sd_event_source*, uint64_t, void* userdata) {
    static_cast<TeensyPort*>(userdata)->turn_step();
    return 0;
}

void TeensyPort::turn_step() {
    // Drive the handshake without blocking: send what it asks for, then sleep until it
    // wants the next poll.
    const auto step = link_.advance(handshake_);
    switch (step.action) {
    case teensy::ConfirmHandshake::Action::Wait:
        sd_event_source_set_time(turn_source_.get(), step.at_ns / 1000);
        sd_event_source_set_enabled(turn_source_.get(), SD_EVENT_ONESHOT);
        return;
    case teensy::ConfirmHandshake::Action::Done:
        finish_turn({});
        return;
    case teensy::ConfirmHandshake::Action::Send: // advance() never stops on a Send
    case teensy::ConfirmHandshake::Action::Failed:
    case teensy::ConfirmHandshake::Action::Idle:
        finish_turn(teensy_result(step.error == teensy::TeensyError::None ? teensy::TeensyError::LinkError : step.error,
                                  "turn confirmation"));
        return;
    }
}

void TeensyPort::finish_turn(const Result& r) {
    tm_.turning = false;
    auto done = std::move(turn_done_);
    turn_done_ = nullptr;
    turn_source_.reset();
    if (done)
        done(r);
}

} // namespace caracara
