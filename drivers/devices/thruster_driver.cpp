#include "drivers/devices/thruster_driver.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <stdexcept>

namespace caracara {

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

IoError ThrusterDriver::send_order(int32_t value) {
    // Commands are accepted or refused above (daemon/vehicle/command_acceptance); here only the
    // wire is protected: held to its range, and never INT32_MIN negated (undefined).
    const int32_t motor_value = std::clamp(value, -kMotorMax, kMotorMax);
    const int32_t wire_value = cfg_.reversed ? -motor_value : motor_value;
    const auto speed = motor_to_speed(wire_value);
    const auto order = speed ? encode_order(cfg_.mt, *speed, cfg_.info) : std::nullopt;
    if (!order) {  // unreachable after the clamp and config validation; refuse anyway
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
