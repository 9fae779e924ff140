// SeaBotix thruster driver over i2c-dev: one I2C_RDWR per thruster transaction (the
// bcm2835 and Pi 5 controllers allow nothing fancier), optional PCA9544A multiplexer in
// front of same-address thrusters, counters and an online flag for telemetry.
// Never throws or allocates on the per-tick paths; a failing thruster is retried every tick.
#pragma once

#include "errors.hpp"
#include "i2c_dev.hpp"
#include "seabotix.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace caracara {

// PCA9544A: 4-channel I2C multiplexer, 7-bit address 1110 A2 A1 A0 (0x70..0x77). Its one
// control register is written with a single byte: bit 2 enables, bits 1-0 pick the channel;
// 0x00 disconnects every channel.
inline constexpr uint16_t kMuxAddrMin = 0x70;
inline constexpr uint16_t kMuxAddrMax = 0x77;
inline constexpr uint16_t kDefaultMuxAddr7 = 0x70;
inline constexpr uint8_t kMuxChannels = 4;
inline constexpr uint8_t kMuxDisableAll = 0x00;
constexpr uint8_t mux_control_byte(uint8_t channel) { return static_cast<uint8_t>(0x04 | (channel & 0x03)); }
constexpr bool is_valid_mux_addr7(uint16_t addr7) { return addr7 >= kMuxAddrMin && addr7 <= kMuxAddrMax; }

// Remembers what each PCA9544A on one bus has selected, so a thruster behind a mux costs
// a control write only when the channel changes. Same-address thrusters may sit behind
// different muxes, so at most one mux has a channel enabled at any time: selecting on one
// first disables every other known mux whose state is not known to be "all off".
class MuxTracker {
public:
    MuxTracker() { invalidate(); }

    // Makes `addr7` known to the tracker (state unknown), so selects on other muxes disable it.
    void add_mux(uint16_t addr7);
    // Ensures `channel` is the only enabled channel of the muxes on this bus. Each control
    // write is its own I2C_RDWR. On failure the state of the mux that failed becomes unknown.
    // IoError::Other without bus traffic for an address outside 0x70..0x77 or channel > 3.
    IoError select(I2cDev& bus, uint16_t addr7, uint8_t channel);
    // Forget all state (after any bus error, recovery or reopen): the next select writes again.
    void invalidate();
    void invalidate(uint16_t addr7);

    // Inspection, for telemetry and tests.
    bool known(uint16_t addr7) const;
    std::optional<uint8_t> selected_channel(uint16_t addr7) const;  // known to be enabled
    bool known_disabled(uint16_t addr7) const;
    uint64_t control_writes() const { return control_writes_; }
    uint64_t control_failures() const { return control_failures_; }

private:
    static constexpr int8_t kUnknown = -1;
    static constexpr int8_t kDisabled = -2;
    IoError write_control(I2cDev& bus, std::size_t index, uint8_t value);

    std::array<bool, 8> known_{};
    std::array<int8_t, 8> state_{};  // channel 0..3, kUnknown or kDisabled
    uint64_t control_writes_ = 0;
    uint64_t control_failures_ = 0;
};

struct MuxRoute {
    uint16_t addr7 = kDefaultMuxAddr7;  // PCA9544A 7-bit address
    uint8_t channel = 0;                // 0..3
};

struct ThrusterConfig {
    uint8_t mt = default_mt(Variant::SeaBotix);  // 8-bit write address byte (even); addr7 = mt >> 1
    Variant variant = Variant::SeaBotix;
    uint8_t info = kDefaultInfo;
    std::optional<MuxRoute> mux;                 // when the thruster sits behind a PCA9544A
    bool reversed = false;                       // negate motor values (mounting direction)
};

// "" when valid, else a message naming the bad field.
std::string validate_thruster_config(const ThrusterConfig& cfg);
// Whole-bus checks on top of validate_thruster_config: no two thrusters reachable at the same
// (mux, channel, address); a thruster on the trunk (no mux) shares its address with no other
// thruster, because an enabled mux channel joins its segment to the trunk; no thruster uses
// the address of a mux on the bus.
std::string validate_thruster_set(std::span<const ThrusterConfig> set);

struct ThrusterCounters {
    uint64_t orders_sent = 0;      // orders the thruster ACKed
    uint64_t order_failures = 0;   // orders not delivered (mux or thruster transfer failed)
    uint64_t rejected_orders = 0;  // motor values outside -8850..8850: refused, nothing sent
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

    // Orders `motor_value` (-8850..+8850; negated first when cfg.reversed): selects the mux
    // channel if needed, then ONE I2C_RDWR with one write message [SPEED, INFO, CSUM] to
    // addr7. An out-of-range value is refused with IoError::Other and nothing is sent.
    IoError send_order(int32_t motor_value);
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
    std::optional<uint8_t> last_speed() const { return last_speed_; }        // last ACKed SPEED byte
    std::optional<int32_t> last_motor_value() const { return last_motor_; } // its value, before reversal
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
    std::optional<uint8_t> last_speed_;
    std::optional<int32_t> last_motor_;
    std::optional<ThrusterStatus> last_status_;
    std::array<uint8_t, kMaxStatusLength> rx_{};
    std::size_t rx_len_ = 0;
};

} // namespace caracara
