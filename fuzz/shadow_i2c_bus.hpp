// The I2C bus under fuzz_seabotix: a DeviceIo whose I2C_RDWR is answered from the fuzz input
// (ACK, NACK, timeout, EIO, a short transfer) while it keeps the PCA9544A control registers as
// the chips would hold them, so the harness can check the tracker's promise on the wire itself:
// a thruster transaction reaches exactly the thruster meant, through exactly its mux channel.
#pragma once

#include "core/thruster_config.hpp"
#include "fuzz/byte_source.hpp"
#include "fuzz/check.hpp"
#include "drivers/platform/device_io.hpp"

#include <array>
#include <cerrno>
#include <cstdint>
#include <linux/i2c-dev.h>
#include <linux/i2c.h>
#include <vector>

namespace caracara::fuzz {

class ShadowI2cBus final : public DeviceIo {
public:
    ShadowI2cBus(ByteSource& in, std::vector<ThrusterConfig> thrusters) : in_(in), thrusters_(std::move(thrusters)) {
        for (const ThrusterConfig& t : thrusters_)
            if (t.mux)
                mux_present_[t.mux->addr7 - kMuxAddrMin] = true;
    }

    // What a mux holds at the start (left over from before the daemon ran) and after a brown-out.
    void set_mux_control(std::size_t i, uint8_t v) { control_[i] = static_cast<uint8_t>(v & 0x07); }
    void reset_mux(std::size_t i) {
        control_[i] = 0;
        reset_since_write_[i] = true;
    }
    uint8_t mux_control(std::size_t i) const { return control_[i]; }
    bool mux_present(std::size_t i) const { return mux_present_[i]; }

    // Set by the harness before each driver call.
    int target = -1;                 // the thruster the call is about
    std::vector<uint8_t> reply;      // what that thruster answers a read with
    // Recorded for the harness.
    uint64_t transactions = 0;
    bool target_reached = false;     // the target's transfer was ACKed
    std::vector<uint8_t> written;    // the bytes of the last write that reached the target

    int open(const char*, int) override { return 3; }
    int close(int) override { return 0; }
    int write(int, const void*, size_t) override { return -EBADF; }
    int ioctl(int fd, unsigned long request, void* arg) override {
        FUZZ_CHECK(fd == 3, "ioctl on fd %d", fd);
        if (request == I2C_FUNCS) {
            *static_cast<unsigned long*>(arg) = I2C_FUNC_I2C;
            return 0;
        }
        FUZZ_CHECK(request == I2C_RDWR, "unexpected ioctl %#lx", request);
        const auto* d = static_cast<const i2c_rdwr_ioctl_data*>(arg);
        // bcm2835 allows one read, last; the driver sends one message per transaction.
        FUZZ_CHECK(d->nmsgs == 1, "%u messages in one I2C_RDWR", d->nmsgs);
        ++transactions;
        return transfer(d->msgs[0]);
    }

private:
    // Which devices answer at addr7 now: muxes sit on the trunk; a thruster answers when it is
    // on the trunk or its mux has its channel enabled.
    std::vector<int> answering(uint16_t addr7, int& muxes) const {
        std::vector<int> who;
        muxes = is_valid_mux_addr7(addr7) && mux_present_[addr7 - kMuxAddrMin] ? 1 : 0;
        for (std::size_t i = 0; i < thrusters_.size(); ++i) {
            const ThrusterConfig& t = thrusters_[i];
            if (mt_addr7(t.mt) != addr7)
                continue;
            if (!t.mux || control_[t.mux->addr7 - kMuxAddrMin] == (0x04 | t.mux->channel))
                who.push_back(static_cast<int>(i));
        }
        return who;
    }

    int fault() {
        // Low bits 0..3: the transfer goes through; 4..7: it fails as i2c-bcm2835 reports it.
        switch (last_fault_ = in_.u8(); last_fault_ & 0x07) {
        case 4: return -ENXIO;      // NACK
        case 5: return -ETIMEDOUT;
        case 6: return -EIO;        // clock stretch / bus error
        case 7: return 0;           // the kernel ran fewer messages than asked
        default: return 1;
        }
    }

    int transfer(i2c_msg& m) {
        int muxes = 0;
        const std::vector<int> who = answering(m.addr, muxes);
        FUZZ_CHECK(muxes + who.size() <= 1, "%zu devices answer at %#x at once", muxes + who.size(), m.addr);
        if (muxes) {
            FUZZ_CHECK(!(m.flags & I2C_M_RD) && m.len == 1, "mux %#x: not a one-byte control write", m.addr);
            const int r = fault();
            // A failed write may still have latched in the chip (bit 3 of the fault byte).
            if (r == 1 || (last_fault_ & 0x08)) {
                control_[m.addr - kMuxAddrMin] = static_cast<uint8_t>(m.buf[0] & 0x07);
                reset_since_write_[m.addr - kMuxAddrMin] = false;
            }
            return r;
        }
        FUZZ_CHECK(target >= 0, "bus traffic to %#x outside a driver call", m.addr);
        const ThrusterConfig& t = thrusters_[static_cast<std::size_t>(target)];
        FUZZ_CHECK(m.addr == mt_addr7(t.mt), "thruster %d's call went to %#x", target, m.addr);
        if (who.empty()) {
            // Only a mux that lost its setting behind the tracker's back may leave it unreached.
            FUZZ_CHECK(t.mux && reset_since_write_[t.mux->addr7 - kMuxAddrMin],
                       "thruster %d unreachable: mux %#x holds %#x", target, t.mux ? t.mux->addr7 : 0,
                       t.mux ? control_[t.mux->addr7 - kMuxAddrMin] : 0);
            return -ENXIO;
        }
        FUZZ_CHECK(who.front() == target, "thruster %d's call reached thruster %d", target, who.front());
        if (t.mux) {
            // The tracker's promise: no other mux has a channel enabled.
            for (std::size_t i = 0; i < 8; ++i)
                FUZZ_CHECK(i == t.mux->addr7 - kMuxAddrMin || !mux_present_[i] || !(control_[i] & 0x04),
                           "mux %#zx enabled (%#x) during thruster %d's transfer", kMuxAddrMin + i, control_[i],
                           target);
        }
        const int r = fault();
        if (r != 1)
            return r;
        target_reached = true;
        if (m.flags & I2C_M_RD) {
            FUZZ_CHECK(m.len == reply.size(), "read of %u bytes, reply has %zu", m.len, reply.size());
            std::copy(reply.begin(), reply.end(), m.buf);
        } else {
            written.assign(m.buf, m.buf + m.len);
        }
        return 1;
    }

    ByteSource& in_;
    std::vector<ThrusterConfig> thrusters_;
    std::array<bool, 8> mux_present_{};
    std::array<uint8_t, 8> control_{};
    std::array<bool, 8> reset_since_write_{};
    uint8_t last_fault_ = 0;
};

} // namespace caracara::fuzz
