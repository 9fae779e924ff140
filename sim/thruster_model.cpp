#include "sim/thruster_model.hpp"

#include <algorithm>
#include <cmath>

namespace caracara::sim {

namespace {
constexpr double kRampPerSecond = 4.0;      // full scale in 250 ms
constexpr double kFullCurrentA = 12.0;      // at full speed, brushless
constexpr double kHeatPerA2 = 0.05;         // degC per second per A^2
constexpr double kCoolingPerSecond = 0.1;   // fraction of the excess lost per second
constexpr double kOvertempSetC = 110.0;     // IDS: set at 110C
constexpr double kOvertempClearC = 100.0;   // IDS: clear at 100C
constexpr uint8_t kLatching = kGroundFault; // until power cycle, both variants
} // namespace

ThrusterModel::ThrusterModel(ThrusterSpec spec) : spec_(spec) {}

bool ThrusterModel::ack_address(bool) { return !nack_; }

void ThrusterModel::on_write(std::span<const uint8_t> data, uint64_t now_ns) {
    last_order_raw_.assign(data.begin(), data.end());
    last_order_time_ns_ = now_ns;
    // IDS 6.6.1: an order with an invalid checksum is discarded.
    if (data.size() != 3) {
        ++orders_rejected_;
        return;
    }
    const uint8_t sum = static_cast<uint8_t>(spec_.mt + data[0] + data[1]);
    if (sum != data[2] || data[0] < 0x19 || data[0] > 0xE6) {
        ++orders_rejected_;
        return;
    }
    ordered_speed_ = data[0];
    info_ = data[1];
    ++orders_received_;
    if (ordered_speed_ == 0x7F || ordered_speed_ == 0x80)
        ++zero_orders_;
}

std::vector<uint8_t> ThrusterModel::status_bytes() const {
    const uint8_t mt_read = static_cast<uint8_t>(spec_.mt | 1);
    std::vector<uint8_t> s;
    if (spec_.variant == ThrusterVariant::SeaBotix) {
        const uint8_t status = static_cast<uint8_t>(spec_.brushless ? 0x02 : 0x00); // rev 0, current limited
        const uint8_t current = static_cast<uint8_t>(std::clamp(std::lround(current_a_ * 10.0), 0L, 255L));
        const uint8_t temp = static_cast<uint8_t>(std::clamp(std::lround(temperature_c_), 0L, 255L));
        s = {mt_read, status, faults_, current, actual_speed_byte(), temp};
        if (replayed_)
            s = {mt_read, status, replayed_->faults, replayed_->current_da, replayed_->speed_byte, replayed_->temperature_c};
    } else {
        // Revision code 1 (Aveox brushless, bit 5) reports current in MAX POWER;
        // revision 2 (legacy brushed, bit 6) reports the power set into the motor.
        const uint8_t faults = replayed_ ? replayed_->faults : faults_;
        uint8_t status = static_cast<uint8_t>((spec_.brushless ? 0x20 : 0x40) | (faults & 0x1F));
        uint8_t max_power = spec_.brushless
            ? static_cast<uint8_t>(std::clamp(std::lround(current_a_ * 10.0), 0L, 255L))
            : actual_speed_byte();
        s = {mt_read, status, max_power};
    }
    uint8_t sum = 0;
    for (uint8_t b : s)
        sum = static_cast<uint8_t>(sum + b);
    s.push_back(sum);
    return s;
}

void ThrusterModel::on_read(std::span<uint8_t> out, uint64_t) {
    ++status_reads_;
    std::vector<uint8_t> s = status_bytes();
    if (corrupt_count_ > 0) {
        --corrupt_count_;
        if (corrupt_how_ == Corrupt::Checksum)
            s.back() = static_cast<uint8_t>(s.back() ^ 0x5A);
        else
            s.front() = static_cast<uint8_t>(s.front() ^ 0x02);
    }
    // A master that reads past the reply sees the released bus: all ones.
    for (size_t i = 0; i < out.size(); ++i)
        out[i] = i < s.size() ? s[i] : 0xFF;
}

double ThrusterModel::fraction_from_speed_byte(uint8_t speed) {
    if (speed >= 0x81)
        return (speed - 0x80) / 102.0;
    if (speed <= 0x7E)
        return -((0x7F - speed) / 102.0);
    return 0.0;
}

uint8_t ThrusterModel::actual_speed_byte() const {
    const long steps = std::lround(std::fabs(actual_) * 102.0);
    if (steps == 0)
        return 0x80;
    return static_cast<uint8_t>(actual_ > 0 ? 0x80 + steps : 0x7F - steps);
}

bool ThrusterModel::motor_stopped_by_fault() const {
    uint8_t stopping = kOvertemp | kStall | kHall | kGroundFault;
    if (spec_.variant == ThrusterVariant::Legacy)
        stopping |= kWaterDetect; // legacy: water detect stops the motor until power cycle
    return (faults_ & stopping) != 0;
}

void ThrusterModel::step(double dt_s, uint64_t) {
    const double target = motor_stopped_by_fault() ? 0.0 : fraction_from_speed_byte(ordered_speed_);
    const double max_delta = kRampPerSecond * dt_s;
    actual_ += std::clamp(target - actual_, -max_delta, max_delta);
    current_a_ = spec_.brushless ? kFullCurrentA * std::pow(std::fabs(actual_), 1.5) : 0.0;
    temperature_c_ += (kHeatPerA2 * current_a_ * current_a_ - kCoolingPerSecond * (temperature_c_ - water_temp_c_)) * dt_s;

    uint8_t live = injected_;
    // Overtemp has hysteresis (IDS remark 6); latched bits stay until power cycle.
    if (temperature_c_ >= kOvertempSetC || ((faults_ & kOvertemp) && temperature_c_ > kOvertempClearC))
        live |= kOvertemp;
    live |= faults_ & kLatching;
    if (spec_.variant == ThrusterVariant::Legacy)
        live |= faults_ & kWaterDetect;
    faults_ = live;
}

void ThrusterModel::set_fault(uint8_t bit, bool on) {
    if (on) {
        injected_ |= bit;
        faults_ |= bit;
    } else {
        injected_ = static_cast<uint8_t>(injected_ & ~bit);
        // Clearing the cause does not clear a latched fault; that takes a power cycle.
        const bool latched = (bit & kLatching) || (spec_.variant == ThrusterVariant::Legacy && (bit & kWaterDetect));
        if (!latched)
            faults_ = static_cast<uint8_t>(faults_ & ~bit);
    }
}

void ThrusterModel::power_cycle() {
    faults_ = injected_;
    ordered_speed_ = 0x80;
    info_ = 100;
    actual_ = 0.0;
}

} // namespace caracara::sim
