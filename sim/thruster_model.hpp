// A simulated SeaBotix thruster controller of either variant (IDS section 8), written from
// the spec independently of the daemon's codec so that each checks the other.
#pragma once

#include "sim/i2c_slave.hpp"
#include "sim/stepped.hpp"
#include "sim/thruster_fault_bits.hpp"
#include "sim/thruster_spec.hpp"

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace caracara::sim {

class ThrusterModel final : public I2cSlave, public Stepped {
public:
    explicit ThrusterModel(ThrusterSpec spec);

    bool ack_address(bool read) override;
    void on_write(std::span<const uint8_t> data, uint64_t now_ns) override;
    void on_read(std::span<uint8_t> out, uint64_t now_ns) override;
    void step(double dt_s, uint64_t now_ns) override;

    // Fault injection.
    void set_fault(uint8_t bit, bool on);
    void set_nack(bool on) { nack_ = on; }
    // Every transfer to this thruster hangs for `ms` (its controller stretches the clock):
    // up to the adapter's I2C_TIMEOUT, after which the transfer fails with ETIMEDOUT.
    void set_hang_ms(uint32_t ms) { hang_ms_ = ms; }
    uint32_t hang_ms() const { return hang_ms_; }
    uint64_t stretch_ns() const override { return uint64_t(hang_ms_) * 1'000'000ull; }
    enum class Corrupt { Checksum, FirstByte };
    void corrupt_replies(uint32_t count, Corrupt how) { corrupt_count_ = count; corrupt_how_ = how; }
    void power_cycle();
    // caracara-sim --replay: status replies carry these instead of the model's (nullopt: the model).
    struct Replayed {
        uint8_t speed_byte = 0x80;
        uint8_t current_da = 0;
        uint8_t temperature_c = 0;
        uint8_t faults = 0;
    };
    void replay(const std::optional<Replayed>& r) { replayed_ = r; }
    void set_water_temperature(double c) { water_temp_c_ = c; }
    // The motor's temperature now (it heats and cools from there); overtemp follows at the next step.
    void set_temperature(double c) { temperature_c_ = c; }

    // Inspection.
    const ThrusterSpec& spec() const { return spec_; }
    uint16_t addr7() const { return spec_.mt >> 1; }
    const std::vector<uint8_t>& last_order_raw() const { return last_order_raw_; }
    uint64_t last_order_time_ns() const { return last_order_time_ns_; }
    uint8_t ordered_speed() const { return ordered_speed_; }
    uint8_t info() const { return info_; }
    uint8_t actual_speed_byte() const;
    double actual_fraction() const { return actual_; } // -1..+1 of full speed
    double current_a() const { return current_a_; }
    double temperature_c() const { return temperature_c_; }
    uint8_t faults() const { return faults_; }
    bool nack() const { return nack_; }
    uint64_t orders_received() const { return orders_received_; }
    uint64_t orders_rejected() const { return orders_rejected_; }
    uint64_t status_reads() const { return status_reads_; }
    uint64_t zero_orders() const { return zero_orders_; }
    std::vector<uint8_t> status_bytes() const; // what a read would return now (uncorrupted)

private:
    bool motor_stopped_by_fault() const;
    static double fraction_from_speed_byte(uint8_t speed);

    ThrusterSpec spec_;
    uint8_t ordered_speed_ = 0x80;
    uint8_t info_ = 100;
    double actual_ = 0.0;
    double current_a_ = 0.0;
    double water_temp_c_ = 15.0;
    double temperature_c_ = 15.0;
    uint8_t faults_ = 0;           // live fault bits
    uint8_t injected_ = 0;         // bits forced by fault injection
    bool nack_ = false;
    uint32_t hang_ms_ = 0;
    uint32_t corrupt_count_ = 0;
    Corrupt corrupt_how_ = Corrupt::Checksum;
    std::vector<uint8_t> last_order_raw_;
    uint64_t last_order_time_ns_ = 0;
    uint64_t orders_received_ = 0;
    uint64_t orders_rejected_ = 0;
    uint64_t status_reads_ = 0;
    uint64_t zero_orders_ = 0;
    std::optional<Replayed> replayed_;
};

} // namespace caracara::sim
