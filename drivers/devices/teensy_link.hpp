// The Teensy frame engine: sends one encoded frame over SpiDev, classifies the reply, resends
// busy frames after a short delay with bounded retries (teensy::RetryTracker decides), and
// counts what happened. Single owner (the control loop); not thread-safe. No heap per frame.
#pragma once

#include "drivers/platform/spi_dev.hpp"
#include "drivers/protocol/confirm_handshake.hpp"
#include "drivers/protocol/retry_tracker.hpp"
#include "drivers/protocol/teensy_codec.hpp"

#include <cstdint>

namespace caracara {

struct TeensyLinkCounters {
    uint64_t frames = 0;         // every frame clocked out, resends included
    uint64_t busy_retries = 0;   // resends because the ack slot was 0xFF
    uint64_t link_errors = 0;    // replies whose ack slot was neither the command nor 0xFF
    uint64_t link_retries = 0;   // resends after a link error (idempotent commands only)
    uint64_t busy_exhausted = 0; // frames given up on while still busy
    uint64_t bad_answers = 0;    // acked frames whose answer was not a value
    uint64_t io_errors = 0;      // SPI transfers the kernel (or simulator) failed
};

class TeensyLink {
public:
    explicit TeensyLink(SpiDev& spi, TeensyLinkConfig config = {}) : spi_(spi), config_(config) {}

    // Sends `frame` until it is acked, busy retries run out, or a link/IO error ends it.
    // On success `value` is the decoded reply (status Ok, answer bytes filled in).
    // Drives a Confirm handshake: sends the frames it asks for, feeding each answer back,
    // until it asks to wait, is done or failed; returns that step. One home for the loop the
    // daemon's Turn and the tests share.
    teensy::ConfirmHandshake::Step advance(teensy::ConfirmHandshake& handshake);
    teensy::TeensyResult<teensy::Reply> execute(const teensy::Frame& frame);

    // Each validates its arguments (TeensyLimits from the config) before anything is sent.
    teensy::TeensyError set_speed(int left, int right);
    teensy::TeensyError turn(double radians);
    teensy::TeensyError turn_to(double heading_radians);
    teensy::TeensyError stop(int brake_duty);
    teensy::TeensyError servo(int servo_id, int degrees);
    teensy::TeensyResult<uint16_t> get_distance(int sensor_id);
    teensy::TeensyResult<float> get_orientation(int axis);
    teensy::TeensyError set_leds(int red, int green, int blue);
    // value 0 polls "finished yet?" (answer 0xFF = finished); a positive value acknowledges.
    teensy::TeensyResult<uint8_t> confirm(uint8_t value);

    const TeensyLinkCounters& counters() const { return counters_; }
    const TeensyLinkConfig& config() const { return config_; }
    // errno of the last TeensyError::Io.
    int last_errno() const { return last_errno_; }

private:
    teensy::TeensyError run(const teensy::TeensyResult<teensy::Frame>& encoded);

    SpiDev& spi_;
    TeensyLinkConfig config_;
    TeensyLinkCounters counters_{};
    int last_errno_ = 0;
};

} // namespace caracara
