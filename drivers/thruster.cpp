#include "thruster.hpp"

#include <cerrno>
#include <cstdio>
#include <stdexcept>

namespace caracara {

namespace {

std::string hex(unsigned v) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "0x%02x", v & 0xFFu);
    return buf;
}

std::size_t mux_index(uint16_t addr7) { return static_cast<std::size_t>(addr7 - kMuxAddrMin); }

} // namespace

// --- MuxTracker ----------------------------------------------------------------------------

void MuxTracker::add_mux(uint16_t addr7) {
    if (!is_valid_mux_addr7(addr7))
        return;
    const std::size_t i = mux_index(addr7);
    if (!known_[i]) {
        known_[i] = true;
        state_[i] = kUnknown;
    }
}

IoError MuxTracker::write_control(I2cDev& bus, std::size_t index, uint8_t value) {
    const std::array<uint8_t, 1> byte{value};
    ++control_writes_;
    const IoError e = bus.write(static_cast<uint16_t>(kMuxAddrMin + index), byte);
    if (e != IoError::None) {
        ++control_failures_;
        state_[index] = kUnknown;
    }
    return e;
}

IoError MuxTracker::select(I2cDev& bus, uint16_t addr7, uint8_t channel) {
    if (!is_valid_mux_addr7(addr7) || channel >= kMuxChannels)
        return IoError::Other;
    add_mux(addr7);
    const std::size_t target = mux_index(addr7);
    // Another mux with a channel enabled (or in an unknown state, e.g. left over from a
    // previous run) could put a same-address thruster on the bus next to ours.
    for (std::size_t i = 0; i < known_.size(); ++i) {
        if (i == target || !known_[i] || state_[i] == kDisabled)
            continue;
        const IoError e = write_control(bus, i, kMuxDisableAll);
        if (e != IoError::None)
            return e;
        state_[i] = kDisabled;
    }
    if (state_[target] == static_cast<int8_t>(channel))
        return IoError::None;
    const IoError e = write_control(bus, target, mux_control_byte(channel));
    if (e != IoError::None)
        return e;
    state_[target] = static_cast<int8_t>(channel);
    return IoError::None;
}

void MuxTracker::invalidate() { state_.fill(kUnknown); }

void MuxTracker::invalidate(uint16_t addr7) {
    if (is_valid_mux_addr7(addr7))
        state_[mux_index(addr7)] = kUnknown;
}

bool MuxTracker::known(uint16_t addr7) const { return is_valid_mux_addr7(addr7) && known_[mux_index(addr7)]; }

std::optional<uint8_t> MuxTracker::selected_channel(uint16_t addr7) const {
    if (!known(addr7) || state_[mux_index(addr7)] < 0)
        return std::nullopt;
    return static_cast<uint8_t>(state_[mux_index(addr7)]);
}

bool MuxTracker::known_disabled(uint16_t addr7) const {
    return known(addr7) && state_[mux_index(addr7)] == kDisabled;
}

// --- configuration -------------------------------------------------------------------------

std::string validate_thruster_config(const ThrusterConfig& cfg) {
    if (!is_valid_mt(cfg.mt))
        return "mt " + hex(cfg.mt) + " is not an even 8-bit write address in 0x10..0xee";
    if (cfg.mux) {
        if (!is_valid_mux_addr7(cfg.mux->addr7))
            return "mux address " + hex(cfg.mux->addr7) + " is not a PCA9544A address (0x70..0x77)";
        if (cfg.mux->channel >= kMuxChannels)
            return "mux channel " + std::to_string(cfg.mux->channel) + " is not 0..3";
    }
    return {};
}

std::string validate_thruster_set(std::span<const ThrusterConfig> set) {
    for (std::size_t i = 0; i < set.size(); ++i) {
        const std::string err = validate_thruster_config(set[i]);
        if (!err.empty())
            return "thruster " + std::to_string(i) + ": " + err;
    }
    for (std::size_t i = 0; i < set.size(); ++i) {
        const ThrusterConfig& a = set[i];
        const uint16_t a7 = mt_addr7(a.mt);
        for (const ThrusterConfig& m : set)
            if (m.mux && m.mux->addr7 == a7)
                return "thruster " + std::to_string(i) + ": address " + hex(a7) + " is a mux address";
        for (std::size_t j = i + 1; j < set.size(); ++j) {
            const ThrusterConfig& b = set[j];
            if (mt_addr7(b.mt) != a7)
                continue;
            const bool distinct_segments = a.mux && b.mux &&
                                           (a.mux->addr7 != b.mux->addr7 || a.mux->channel != b.mux->channel);
            if (!distinct_segments)
                return "thrusters " + std::to_string(i) + " and " + std::to_string(j) + " share address " + hex(a7) +
                       " on one bus segment";
        }
    }
    return {};
}

// --- ThrusterDriver ------------------------------------------------------------------------

ThrusterDriver::ThrusterDriver(I2cDev& bus, MuxTracker& mux, ThrusterConfig cfg)
    : bus_(&bus), mux_(&mux), cfg_(cfg) {
    const std::string err = validate_thruster_config(cfg_);
    if (!err.empty())
        throw std::invalid_argument(err);
    if (cfg_.mux)
        mux_->add_mux(cfg_.mux->addr7);
}

void ThrusterDriver::count_io_error(IoError e) {
    switch (e) {
    case IoError::Nack: ++counters_.nacks; break;
    case IoError::Timeout: ++counters_.timeouts; break;
    case IoError::ClockStretch: ++counters_.clock_stretch; break;
    case IoError::BadReply: break;  // counted by read_status with its cause
    case IoError::None: break;
    case IoError::Arbitration:
    case IoError::NoDevice:
    case IoError::Unsupported:
    case IoError::Other: ++counters_.other_errors; break;
    }
}

void ThrusterDriver::note_failure(IoError e, int err) {
    online_ = false;
    last_error_ = e;
    last_errno_ = err;
    count_io_error(e);
    // A NACK or a garbled reply may mean our mux lost its selection (reset, brown-out);
    // anything else may have disturbed the whole bus. Re-selecting costs one byte.
    if (e == IoError::Nack || e == IoError::BadReply) {
        if (cfg_.mux)
            mux_->invalidate(cfg_.mux->addr7);
    } else {
        mux_->invalidate();
    }
}

IoError ThrusterDriver::select_mux() {
    if (!cfg_.mux)
        return IoError::None;
    const IoError e = mux_->select(*bus_, cfg_.mux->addr7, cfg_.mux->channel);
    if (e != IoError::None) {
        ++counters_.mux_failures;
        note_failure(e, bus_->last_errno());
    }
    return e;
}

IoError ThrusterDriver::send_order(int32_t motor_value) {
    // Range first: negating an out-of-range value (INT32_MIN) would be undefined.
    if (motor_value < -kMotorMax || motor_value > kMotorMax) {
        ++counters_.rejected_orders;
        return IoError::Other;
    }
    const int32_t wire_value = cfg_.reversed ? -motor_value : motor_value;
    const auto speed = motor_to_speed(wire_value);
    const auto order = speed ? encode_order(cfg_.mt, *speed, cfg_.info) : std::nullopt;
    if (!order) {  // unreachable after the range check and config validation; refuse anyway
        ++counters_.rejected_orders;
        return IoError::Other;
    }
    if (const IoError e = select_mux(); e != IoError::None) {
        ++counters_.order_failures;
        return e;
    }
    const IoError e = bus_->write(addr7(), *order);
    if (e != IoError::None) {
        ++counters_.order_failures;
        note_failure(e, bus_->last_errno());
        return e;
    }
    ++counters_.orders_sent;
    online_ = true;
    last_speed_ = *speed;
    last_motor_ = motor_value;
    return IoError::None;
}

IoError ThrusterDriver::read_status() {
    if (const IoError e = select_mux(); e != IoError::None) {
        ++counters_.status_failures;
        return e;
    }
    const std::size_t n = status_length(cfg_.variant);
    rx_.fill(0);
    rx_len_ = 0;
    const IoError e = bus_->read(addr7(), std::span<uint8_t>(rx_).first(n));
    if (e != IoError::None) {
        ++counters_.status_failures;
        note_failure(e, bus_->last_errno());
        return e;
    }
    rx_len_ = n;
    const DecodedStatus d = decode_status(cfg_.variant, cfg_.mt, last_reply());
    last_reply_error_ = d.error;
    if (!d.ok()) {
        ++counters_.status_failures;
        ++counters_.bad_replies;
        if (d.error == CodecError::BadFirstByte)
            ++counters_.bad_first_byte;
        else if (d.error == CodecError::BadChecksum)
            ++counters_.bad_checksum;
        note_failure(IoError::BadReply, EBADMSG);
        return IoError::BadReply;
    }
    ++counters_.status_reads;
    online_ = true;
    last_status_ = d.status;
    return IoError::None;
}

} // namespace caracara
