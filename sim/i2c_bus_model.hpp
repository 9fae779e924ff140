// The simulated I2C bus: slaves by 7-bit address, PCA9544A multiplexers in front of some of
// them, wire time at the configured clock, and the wire log. One call = one I2C_RDWR.
#pragma once

#include "core/enum_names.hpp"
#include "sim/i2c_slave.hpp"
#include "sim/pca9544.hpp"
#include "sim/wire_log.hpp"

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <vector>

namespace caracara::sim {

struct I2cMessage {
    uint16_t addr = 0;
    uint16_t flags = 0;         // I2C_M_RD etc.
    std::vector<uint8_t> data;  // write payload, or the read buffer (sized to len)
};

class I2cBusModel {
public:
    I2cBusModel(WireLog& log, uint32_t clock_hz) : log_(log), clock_hz_(clock_hz) {}

    void add_mux(uint16_t addr7);
    // A slave directly on the bus (no mux) or behind channel `channel` of the mux at mux_addr.
    void attach(I2cSlave* slave, uint16_t addr7, std::optional<uint16_t> mux_addr = {}, uint8_t channel = 0);

    struct Result {
        int ret = 0;          // number of messages, or -errno as i2c-dev would return
        uint64_t wire_ns = 0; // time the transaction occupies the wire
        uint64_t held_ns = 0; // of which a slave held the clock (a hung device)
    };
    // `start_ns` is when the transaction begins on the wire; log entries are stamped with
    // the end of each message.
    Result transfer(std::vector<I2cMessage>& msgs, uint64_t start_ns);

    // --- The open-drain wire (bus lockup and its recovery) ---
    // SDA and SCL are the wired-AND of every driver. A slave that lost sync holds SDA low
    // until it has seen `pulses` more SCL clocks (1..9); a broken one holds SCL low for good.
    enum class Hang { None, SdaLow, SclLow };
    void hang_sda(uint32_t pulses) { hang_ = Hang::SdaLow; hang_pulses_needed_ = pulses; hang_pulses_seen_ = 0; }
    void hang_scl() { hang_ = Hang::SclLow; }
    void clear_hang() { hang_ = Hang::None; }
    Hang hang() const { return hang_; }
    uint32_t hang_pulses_seen() const { return hang_pulses_seen_; }
    uint32_t hang_pulses_needed() const { return hang_pulses_needed_; }
    bool slaves_release_sda() const { return hang_ != Hang::SdaLow; }
    bool slaves_release_scl() const { return hang_ != Hang::SclLow; }
    // Called by the GPIO model on every rising edge of the physical SCL line.
    void on_scl_rising(uint64_t now_ns);
    // The SoC pins carry either the I2C controller or GPIO; taking them as GPIO takes them
    // away from I2C until the controller's driver is bound again (as on a Raspberry Pi).
    void set_pins_to_gpio() { i2c_function_ = false; }
    void restore_i2c_function() { i2c_function_ = true; }
    bool i2c_function() const { return i2c_function_; }

    // How long the controller waits for a stretched clock before it gives up with ETIMEDOUT:
    // the adapter's timeout, which I2C_TIMEOUT sets (i2c-bcm2835's default is one second).
    void set_timeout_ns(uint64_t ns) { timeout_ns_ = ns; }
    uint64_t timeout_ns() const { return timeout_ns_; }

    uint32_t clock_hz() const { return clock_hz_; }
    void set_clock_hz(uint32_t hz) { clock_hz_ = hz; }
    uint64_t transactions() const { return transactions_; }
    uint64_t wire_time_ns() const { return wire_time_ns_; }
    uint64_t bit_time_ns() const { return 1000000000ull / clock_hz_; }

private:
    I2cSlave* find(uint16_t addr7) const;

    WireLog& log_;
    uint32_t clock_hz_;
    uint64_t transactions_ = 0;
    Hang hang_ = Hang::None;
    uint32_t hang_pulses_needed_ = 0;
    uint32_t hang_pulses_seen_ = 0;
    bool i2c_function_ = true;
    uint64_t timeout_ns_ = 1'000'000'000ull;
    uint64_t wire_time_ns_ = 0;
    std::map<uint16_t, std::unique_ptr<Pca9544>> muxes_;
    struct Attached {
        I2cSlave* slave;
        uint16_t addr7;
        std::optional<uint16_t> mux;
        uint8_t channel;
    };
    std::vector<Attached> slaves_;
};

} // namespace caracara::sim
namespace caracara {
template <>
struct EnumNames<sim::I2cBusModel::Hang> {
    static constexpr std::array<EnumName<sim::I2cBusModel::Hang>, 3> table{{
        {sim::I2cBusModel::Hang::None, "none"},
        {sim::I2cBusModel::Hang::SdaLow, "sda-low"},
        {sim::I2cBusModel::Hang::SclLow, "scl-low"},
    }};
};
} // namespace caracara
