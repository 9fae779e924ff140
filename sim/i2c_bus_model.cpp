#include "sim/i2c_bus_model.hpp"

#include <algorithm>

#include <cerrno>
#include <linux/i2c.h>

namespace caracara::sim {

void I2cBusModel::add_mux(uint16_t addr7) {
    if (!muxes_.count(addr7))
        muxes_[addr7] = std::make_unique<Pca9544>();
}

void I2cBusModel::attach(I2cSlave* slave, uint16_t addr7, std::optional<uint16_t> mux_addr, uint8_t channel) {
    if (mux_addr)
        add_mux(*mux_addr);
    slaves_.push_back({slave, addr7, mux_addr, channel});
}

I2cSlave* I2cBusModel::find(uint16_t addr7) const {
    if (auto it = muxes_.find(addr7); it != muxes_.end())
        return it->second.get();
    for (const auto& a : slaves_) {
        if (a.addr7 != addr7)
            continue;
        if (!a.mux)
            return a.slave;
        auto sel = muxes_.at(*a.mux)->selected();
        if (sel && *sel == a.channel)
            return a.slave;
    }
    return nullptr;
}

void I2cBusModel::on_scl_rising(uint64_t) {
    if (hang_ != Hang::SdaLow)
        return;
    // The stuck slave finishes the byte it thought it was sending, then lets SDA go.
    if (++hang_pulses_seen_ >= hang_pulses_needed_)
        hang_ = Hang::None;
}

I2cBusModel::Result I2cBusModel::transfer(std::vector<I2cMessage>& msgs, uint64_t start_ns) {
    ++transactions_;
    const uint64_t txn = log_.new_transaction();
    const uint64_t bit = bit_time_ns();
    if (!i2c_function_ || hang_ != Hang::None) {
        // The controller cannot make a START: with SDA held low (or the pins muxed away) it
        // times out; with SCL held low the clock-stretch timeout reports EIO.
        WireEntry e;
        e.transaction = txn;
        e.bus = "i2c";
        e.addr = msgs.empty() ? 0 : msgs.front().addr;
        e.read = !msgs.empty() && (msgs.front().flags & I2C_M_RD);
        e.result = !i2c_function_ ? "pins-not-i2c" : (hang_ == Hang::SclLow ? "scl-held-low" : "sda-held-low");
        const uint64_t timeout_ns = 10 * 9 * bit; // the controller gives up after a few byte times
        e.time_ns = start_ns + timeout_ns;
        log_.append(std::move(e));
        return {hang_ == Hang::SclLow ? -EIO : -ETIMEDOUT, timeout_ns};
    }
    uint64_t t = start_ns;
    Result res{static_cast<int>(msgs.size()), 0};
    for (auto& m : msgs) {
        const bool read = m.flags & I2C_M_RD;
        WireEntry e;
        e.transaction = txn;
        e.bus = "i2c";
        e.addr = m.addr;
        e.read = read;
        t += bit;     // (repeated) START
        t += 9 * bit; // address byte + ACK slot
        I2cSlave* s = (m.flags & I2C_M_TEN) ? nullptr : find(m.addr);
        if (!s || !s->ack_address(read)) {
            // No ACK to the address: the controller sends STOP and i2c-dev reports EREMOTEIO.
            e.result = "nack";
            e.time_ns = t;
            log_.append(std::move(e));
            res.ret = -EREMOTEIO;
            break;
        }
        if (const uint64_t hold = s->stretch_ns(); hold > 0) {
            // The slave holds SCL low; the controller waits up to its timeout.
            const uint64_t waited = std::min(hold, timeout_ns_);
            t += waited;
            res.held_ns += waited;
            if (hold >= timeout_ns_) {
                e.result = "timeout";
                e.time_ns = t;
                log_.append(std::move(e));
                res.ret = -ETIMEDOUT;
                break;
            }
        }
        t += 9 * bit * m.data.size();
        if (read)
            s->on_read(m.data, t);
        else
            s->on_write(m.data, t);
        e.data = m.data;
        e.result = "ack";
        e.time_ns = t;
        log_.append(std::move(e));
    }
    t += bit; // STOP
    res.wire_ns = t - start_ns;
    wire_time_ns_ += res.wire_ns;
    return res;
}

} // namespace caracara::sim
