#include "daemon/teensy/teensy_connection.hpp"

#include "core/clock.hpp"
#include "daemon/loop/log.hpp"
#include "drivers/platform/io_error.hpp"

#include <cerrno>
#include <memory>

namespace caracara {

namespace {
constexpr uint64_t kReopenUs = 1'000'000;
} // namespace

Result teensy_result(teensy::TeensyError e, std::string_view what) {
    if (e == teensy::TeensyError::None)
        return {};
    return {teensy::status_of(e), std::string(what) + ": " + std::string(teensy::teensy_error_name(e))};
}

TeensyConnection::TeensyConnection(sd_event* event, DeviceIo& io, const SpiSettings& settings, CommandGate& gate)
    : event_(event), gate_(gate), spi_(io, settings.device, settings.spi), link_(spi_, settings.teensy), worker_(link_),
      watch_(
          settings, [this] { worker_.collect(); }, [this] { return open_; },
          [this](uint64_t ms) {
              // Silent: asked for this long and no valid frame.
              log_error("Teensy on SPI %s answered no valid frame for %llu ms: failsafe teensy-link-lost",
                        spi_.path().c_str(), static_cast<unsigned long long>(ms));
              lose(TeensyLoss::Silent);
          }) {
    tm_.distances.assign(static_cast<size_t>(settings.teensy.limits.distance_sensor_count), 0);
    tm_.servos.assign(static_cast<size_t>(settings.teensy.limits.servo_count), 0);
}

int TeensyConnection::open() {
    const int r = spi_.open();
    open_ = tm_.online = r >= 0;
    if (r < 0) {
        // Fitted: the vehicle stays killed (the failsafes look at the conditions as they start).
        if (watch_.fitted()) {
            watch_.lose(TeensyLoss::Absent);
            log_error("Teensy is fitted ([spi] fitted) but SPI %s is absent at start (%s): failsafe "
                      "teensy-link-lost; asking for it again once a second",
                      spi_.path().c_str(), errno_name(-r).c_str());
        }
        schedule_reopen(); // a Teensy that comes later is picked up
    }
    return r;
}

void TeensyConnection::close() {
    worker_.stop(); // after the frame on the wire; what was queued (a Stop of the way out) still runs
    reopen_timer_.reset();
    watch_.stop();
    spi_.close();
    open_ = false;
}

void TeensyConnection::schedule_reopen() {
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

int TeensyConnection::on_reopen(sd_event_source*, uint64_t, void* userdata) {
    auto* self = static_cast<TeensyConnection*>(userdata);
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
                             self->watch_.reopened(); // the silence counts from its first frame
                             // Whatever the wheels were doing before, they stop now (as at every start).
                             if (self->on_back_)
                                 self->on_back_();
                             // Online, and teensy-link-lost cleared, at its first valid frame.
                         });
    return 0;
}

void TeensyConnection::lose_link() {
    if (!open_)
        return;
    log_error("Teensy SPI %s went away (%s): failsafe teensy-link-lost; asking for it again once a second",
              spi_.path().c_str(), errno_name(ENODEV).c_str());
    open_ = false;
    worker_.submit([this] { spi_.close(); }, nullptr);
    watch_.gone(); // gone, whatever it was before
    lose(TeensyLoss::Gone);
    schedule_reopen();
}

void TeensyConnection::lose(TeensyLoss why) {
    tm_.online = false;
    if (!watch_.lose(why))
        return;
    if (on_lost_)
        on_lost_();
    gate_.link_changed(); // the kill, at once
}

void TeensyConnection::heard(uint64_t now) {
    const TeensyLoss was = watch_.loss();
    if (!watch_.heard(now)) {
        if (open_)
            tm_.online = true;
        return;
    }
    tm_.online = true;
    log_notice("Teensy answers again (it was %s): teensy-link-lost clears", std::string(name_of(was)).c_str());
    // Whatever the wheels were doing before, they stop now: the kill's Stop may not have got through.
    if (on_back_)
        on_back_();
    gate_.link_changed(); // teensy-link-lost clears
}

std::string TeensyConnection::start(int64_t priority) {
    if (std::string e = worker_.start(event_, priority); !e.empty())
        return e;
    return watch_.start(event_);
}

int TeensyConnection::io_errno(teensy::TeensyError e) const {
    // Only a failed transfer has an errno of its own: the SPI device keeps its last one, which
    // after a garbage answer would be a stale ENODEV from a device that has since come back.
    return e == teensy::TeensyError::Io ? spi_.last_errno() : 0;
}

void TeensyConnection::poll() {
    worker_.collect(); // the last poll's result, if it is in
    if (poll_out_ || !open_)
        return;
    const unsigned sensors = static_cast<unsigned>(tm_.distances.size());
    const unsigned slots = 3 + (sensors ? 1 : 0);
    poll_.slot = poll_index_ % slots;
    ++poll_index_;
    poll_.sensor = sensors ? (poll_index_ / slots) % sensors : 0;
    poll_out_ = true;
    watch_.asked();
    // Captures `this` only: no allocation per poll.
    worker_.submit(
        [this] {
            teensy::TeensyError e = teensy::TeensyError::None;
            if (poll_.slot < 3) {
                auto r = link_.get_orientation(static_cast<int>(poll_.slot));
                e = r.error;
                poll_.value = r.value;
            } else {
                auto r = link_.get_distance(static_cast<int>(poll_.sensor));
                e = r.error;
                poll_.value = r.value;
            }
            poll_.ok = e == teensy::TeensyError::None;
            poll_.err = io_errno(e);
        },
        [this] { poll_done(); }, false);
}

void TeensyConnection::poll_done() {
    poll_out_ = false;
    if (poll_.ok) {
        if (poll_.slot < 3)
            tm_.orientation[poll_.slot] = poll_.value;
        else
            tm_.distances[poll_.sensor] = static_cast<uint16_t>(poll_.value);
        heard(monotonic_ns());
    } else if (poll_.err == ENODEV) {
        lose_link();
    } else {
        tm_.online = false;
    }
}

void TeensyConnection::command(std::function<teensy::TeensyError()> frame, std::string what, Completion done) {
    auto e = std::make_shared<teensy::TeensyError>(teensy::TeensyError::None);
    auto err = std::make_shared<int>(0);
    watch_.asked();
    worker_.submit(
        [this, frame = std::move(frame), e, err] {
            *e = frame();
            *err = io_errno(*e);
        },
        [this, e, err, what = std::move(what), done = std::move(done)] {
            const Result r = teensy_result(*e, what);
            if (r.ok())
                heard(monotonic_ns());
            else if (*err == ENODEV)
                lose_link();
            if (done)
                done(r);
        });
}

} // namespace caracara
