#include "daemon/teensy/teensy_connection.hpp"

#include "core/clock.hpp"
#include "daemon/loop/log.hpp"
#include "drivers/platform/io_error.hpp"

#include <cerrno>
#include <memory>

namespace caracara {

TeensyConnection::TeensyConnection(sd_event* event, DeviceIo& io, const SpiSettings& settings, FailsafeGate& failsafes)
    : event_(event), failsafes_(failsafes), spi_(io, settings.device, settings.spi), link_(spi_, settings.teensy), worker_(link_),
      watch_(
          settings, [this] { worker_.collect(); }, [this] { return open_; },
          [this](uint64_t ms) {
              // Silent: asked for this long and no valid frame.
              log_error("Teensy on SPI %s answered no valid frame for %llu ms: failsafe teensy-link-lost",
                        spi_.path().c_str(), static_cast<unsigned long long>(ms));
              lose(TeensyLoss::Silent, "the Teensy answered no valid frame for " + std::to_string(ms) + " ms");
          }),
      poll_(
          worker_, link_, tm_, [this](teensy::TeensyError e) { return io_errno(e); },
          [this](TeensyPoll::Outcome outcome) { polled(outcome); }),
      reopen_(event, worker_, spi_, [this] { return open_; }, [this] { reopened(); }) {
    tm_.distances.assign(static_cast<size_t>(settings.teensy.limits.distance_sensor_count), 0);
    tm_.servos.assign(static_cast<size_t>(settings.teensy.limits.servo_count), 0);
}

int TeensyConnection::open() {
    const int r = spi_.open();
    open_ = tm_.online = r >= 0;
    if (r < 0) {
        // Fitted: the vehicle stays killed (the failsafes decide what was pushed as they start).
        if (watch_.fitted()) {
            if (watch_.lose(TeensyLoss::Absent))
                failsafes_.push(FailsafeCondition::TeensyLinkLost, true, "the Teensy is fitted but absent at start");
            log_error("Teensy is fitted ([spi] fitted) but SPI %s is absent at start (%s): failsafe "
                      "teensy-link-lost; asking for it again once a second",
                      spi_.path().c_str(), errno_name(-r).c_str());
        }
        reopen_.schedule(); // a Teensy that comes later is picked up
    }
    return r;
}

void TeensyConnection::close() {
    worker_.stop(); // after the frame on the wire; what was queued (a Stop of the way out) still runs
    reopen_.stop();
    watch_.stop();
    spi_.close();
    open_ = false;
}

void TeensyConnection::reopened() {
    log_notice("Teensy SPI %s is back", spi_.path().c_str());
    open_ = true;
    watch_.reopened(); // the silence counts from its first frame
    // Whatever the wheels were doing before, they stop now (as at every start).
    if (on_back_)
        on_back_();
    // Online, and teensy-link-lost cleared, at its first valid frame.
}

void TeensyConnection::lose_link() {
    if (!open_)
        return;
    log_error("Teensy SPI %s went away (%s): failsafe teensy-link-lost; asking for it again once a second",
              spi_.path().c_str(), errno_name(ENODEV).c_str());
    open_ = false;
    worker_.submit([this] { spi_.close(); }, nullptr);
    watch_.gone(); // gone, whatever it was before
    lose(TeensyLoss::Gone, "the Teensy's SPI device went away");
    reopen_.schedule();
}

void TeensyConnection::lose(TeensyLoss why, std::string_view what) {
    tm_.online = false;
    if (!watch_.lose(why))
        return;
    if (on_lost_)
        on_lost_();
    failsafes_.push(FailsafeCondition::TeensyLinkLost, true, what); // the kill, at once
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
    failsafes_.push(FailsafeCondition::TeensyLinkLost, false, "the Teensy answers again");
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
    if (poll_.out() || !open_)
        return;
    watch_.asked();
    poll_.ask();
}

void TeensyConnection::polled(TeensyPoll::Outcome outcome) {
    switch (outcome) {
    case TeensyPoll::Outcome::Answered:
        heard(monotonic_ns());
        break;
    case TeensyPoll::Outcome::Gone:
        lose_link();
        break;
    case TeensyPoll::Outcome::Failed:
        tm_.online = false;
        break;
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
            const Result r = teensy::result_of(*e, what);
            if (r.ok())
                heard(monotonic_ns());
            else if (*err == ENODEV)
                lose_link();
            if (done)
                done(r);
        });
}

} // namespace caracara
