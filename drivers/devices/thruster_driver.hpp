// SeaBotix thruster driver over i2c-dev: one I2C_RDWR per thruster transaction (the
// bcm2835 and Pi 5 controllers allow nothing fancier), optional PCA9544A multiplexer in
// front of same-address thrusters, counters and an online flag for telemetry.
// Never throws or allocates on the per-tick paths; a failing thruster is retried every tick.
#pragma once

#include "drivers/platform/io_error.hpp"
#include "core/thruster_config.hpp"
#include "drivers/devices/mux_tracker.hpp"
#include "drivers/platform/i2c_dev.hpp"
#include "drivers/protocol/seabotix.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace caracara {



struct ThrusterCounters {
    uint64_t orders_sent = 0;      // orders the thruster ACKed
    uint64_t order_failures = 0;   // orders not delivered (mux or thruster transfer failed)
    uint64_t rejected_orders = 0;  // orders the codec refused (never, after the clamp and config validation)
    uint64_t status_reads = 0;     // status replies that decoded cleanly
    uint64_t status_failures = 0;  // status reads that failed (transfer or bad reply)
    uint64_t nacks = 0;            // IoError::Nack, from the thruster or its mux
    uint64_t timeouts = 0;         // IoError::Timeout
    uint64_t clock_stretch = 0;    // IoError::ClockStretch (EIO: stretch timeout / bus error)
    uint64_t other_errors = 0;     // arbitration lost, no device, unsupported, other
    uint64_t bad_replies = 0;      // = bad_first_byte + bad_checksum (+ bad length, not expected)
    uint64_t bad_first_byte = 0;
    uint64_t bad_checksum = 0;
    uint64_t mux_failures = 0;     // transactions that failed at the mux select step
};

class ThrusterDriver {
public:
    // Throws std::invalid_argument when validate_thruster_config(cfg) fails (startup only).
    // Registers the thruster's mux, if any, with `mux`. `bus` and `mux` must outlive the driver.
    ThrusterDriver(I2cDev& bus, MuxTracker& mux, ThrusterConfig cfg);

    // Orders `value` (held to -8850..+8850, the wire's range; negated then when cfg.reversed):
    // selects the mux channel if needed, then ONE I2C_RDWR with one write message [SPEED, INFO,
    // CSUM] to addr7. Refusing a command is the daemon's CommandAcceptance's, not the driver's.
    IoError send_order(int32_t value);
    // ONE I2C_RDWR with one read message of status_length(variant) bytes, decoded. A reply
    // with a wrong first byte or checksum is discarded, counted, and gives IoError::BadReply;
    // last_status() keeps the last good one.
    IoError read_status();

    const ThrusterConfig& config() const { return cfg_; }
    uint16_t addr7() const { return mt_addr7(cfg_.mt); }
    // False until the first successful transaction and after any failure; true again after
    // any successful transaction.
    bool online() const { return online_; }
    const ThrusterCounters& counters() const { return counters_; }
    IoError last_error() const { return last_error_; }        // last failure (kept after recovery)
    int last_errno() const { return last_errno_; }            // its errno (EBADMSG for a bad reply)
    CodecError last_reply_error() const { return last_reply_error_; }
    std::optional<uint8_t> last_speed() const { return last_speed_; } // last ACKed SPEED byte
    const std::optional<ThrusterStatus>& last_status() const { return last_status_; }
    std::span<const uint8_t> last_reply() const { return std::span<const uint8_t>(rx_).first(rx_len_); }

private:
    IoError select_mux();
    void note_failure(IoError e, int err);
    void count_io_error(IoError e);

    I2cDev* bus_;
    MuxTracker* mux_;
    ThrusterConfig cfg_;
    ThrusterCounters counters_;
    bool online_ = false;
    IoError last_error_ = IoError::None;
    int last_errno_ = 0;
    CodecError last_reply_error_ = CodecError::None;
    // Kept: the SPEED byte the thruster last ACKed, the wire's own word (OrderedSpeed), not the order.
    std::optional<uint8_t> last_speed_;
    std::optional<ThrusterStatus> last_status_;
    std::array<uint8_t, kMaxStatusLength> rx_{};
    std::size_t rx_len_ = 0;
};

} // namespace caracara
