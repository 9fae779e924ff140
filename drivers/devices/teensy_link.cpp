#include "drivers/devices/teensy_link.hpp"

#include "core/clock.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <ctime>

namespace caracara {

using namespace teensy;

namespace {

// The busy delay is a few hundred microseconds: sleeping in place is cheaper and simpler than
// handing the frame back to the event loop.
void sleep_us(uint32_t us) {
    if (us == 0)
        return;
    timespec ts{static_cast<time_t>(us / 1000000u), static_cast<long>(us % 1000000u) * 1000L};
    while (nanosleep(&ts, &ts) < 0 && errno == EINTR) {
    }
}

} // namespace

TeensyResult<Reply> TeensyLink::execute(const Frame& frame) {
    const CommandInfo* info = find_command(frame.command());
    if (!info || frame.size != 1u + info->data_len + info->answer_len + 1u)
        return {TeensyError::LinkError, {}}; // not a frame of this protocol: never sent

    RetryTracker tracker(config_.retry, *info);
    std::array<uint8_t, kMaxFrame> rx{};
    for (;;) {
        const std::span<uint8_t> in{rx.data(), frame.size};
        std::fill(in.begin(), in.end(), uint8_t{0});
        ++counters_.frames;
        if (int r = spi_.transfer(frame.span(), in); r < 0) {
            ++counters_.io_errors;
            last_errno_ = -r;
            return {TeensyError::Io, {}};
        }
        const Reply reply = decode_reply(frame, in);
        if (reply.status == FrameStatus::LinkError)
            ++counters_.link_errors;
        const RetryDecision d = tracker.on_reply(reply.status);
        switch (d.action) {
        case RetryAction::Done:
            return {TeensyError::None, reply};
        case RetryAction::ResendAfterDelay:
            if (d.error == TeensyError::Busy)
                ++counters_.busy_retries;
            else
                ++counters_.link_retries;
            sleep_us(config_.retry.busy_delay_us);
            break;
        case RetryAction::Fail:
            if (d.error == TeensyError::BusyExhausted)
                ++counters_.busy_exhausted;
            return {d.error, reply};
        }
    }
}

TeensyError TeensyLink::run(const TeensyResult<Frame>& encoded) {
    if (!encoded.ok())
        return encoded.error;
    TeensyResult<Reply> r = execute(encoded.value);
    return r.ok() ? decode_ack(r.value) : r.error;
}

TeensyError TeensyLink::set_speed(int left, int right) { return run(encode_set_speed(left, right)); }

TeensyError TeensyLink::turn(double radians) { return run(encode_turn(radians)); }

TeensyError TeensyLink::turn_to(double heading_radians) { return run(encode_turn_to(heading_radians)); }

TeensyError TeensyLink::stop(int brake_duty) { return run(encode_stop(brake_duty)); }

TeensyError TeensyLink::servo(int servo_id, int degrees) {
    return run(encode_servo(servo_id, degrees, config_.limits));
}

TeensyError TeensyLink::set_leds(int red, int green, int blue) { return run(encode_set_leds(red, green, blue)); }

TeensyResult<uint16_t> TeensyLink::get_distance(int sensor_id) {
    const TeensyResult<Frame> f = encode_get_distance(sensor_id, config_.limits);
    if (!f.ok())
        return {f.error, 0};
    const TeensyResult<Reply> r = execute(f.value);
    if (!r.ok())
        return {r.error, 0};
    return decode_distance(r.value);
}

TeensyResult<float> TeensyLink::get_orientation(int axis) {
    const TeensyResult<Frame> f = encode_get_orientation(axis);
    if (!f.ok())
        return {f.error, 0.0f};
    const TeensyResult<Reply> r = execute(f.value);
    if (!r.ok())
        return {r.error, 0.0f};
    TeensyResult<float> v = decode_orientation(r.value);
    if (v.error == TeensyError::BadAnswer)
        ++counters_.bad_answers;
    return v;
}

TeensyResult<uint8_t> TeensyLink::confirm(uint8_t value) {
    const TeensyResult<Reply> r = execute(encode_confirm(value).value);
    if (!r.ok())
        return {r.error, 0};
    return decode_confirm(r.value);
}

teensy::ConfirmHandshake::Step TeensyLink::advance(teensy::ConfirmHandshake& handshake) {
    for (;;) {
        auto step = handshake.next(monotonic_ns());
        if (step.action != teensy::ConfirmHandshake::Action::Send)
            return step;
        auto reply = execute(step.frame);
        teensy::TeensyResult<uint8_t> res;
        if (!reply.ok())
            res.error = reply.error;
        else
            res = teensy::decode_confirm(reply.value);
        handshake.on_result(res, monotonic_ns());
    }
}

} // namespace caracara
