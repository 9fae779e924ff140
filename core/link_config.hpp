// Settings of the SPI link to the Teensy, as the configuration gives them to the drivers:
// spidev speed and per-byte delay, the busy/retry policy, the Confirm handshake's timing and
// the firmware's servo and sensor counts (Pi-Teensy SPI protocol; docs/teensy-protocol.md).
#pragma once

#include <cstdint>

namespace caracara {

struct SpiConfig {
    // Public Teensy code ran the link at 500 kHz to 1 MHz; the slower end leaves an
    // interrupt-driven slave the most time per byte.
    uint32_t speed_hz = 500000;
    // 0: one full-duplex transfer per call. Non-zero: one 1-byte transfer per byte, each
    // followed by this delay, so an interrupt-driven slave can load its next byte in time.
    uint16_t byte_delay_us = 0;
};

namespace teensy {

struct TeensyLimits {
    int servo_count = 4;
    int distance_sensor_count = 4;
};

struct RetryPolicy {
    uint32_t busy_delay_us = 200; // the seed's "small delay" before resending a busy frame
    uint8_t max_busy_retries = 10;
    // Resend once after a link error, for idempotent commands only (never Turn).
    bool retry_link_error_once = true;
};

struct ConfirmHandshakeConfig {
    uint64_t poll_interval_ns = 20'000'000; // 20 ms between "finished yet?" polls
    uint64_t timeout_ns = 30'000'000'000;   // a slow full turn fits well inside 30 s
    unsigned ack_attempts = 3;              // tries to deliver the acknowledgement
};

} // namespace teensy

struct TeensyLinkConfig {
    teensy::RetryPolicy retry{};
    teensy::TeensyLimits limits{};
};

} // namespace caracara
