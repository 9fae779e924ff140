// The simulator's device-protocol request decoder (drivers/protocol/sim_protocol.hpp) as the device
// server runs it: DeviceOps::handle against a whole simulated vehicle, fed a sequence of
// requests from one client, as any local peer of the socket could send them. Each request's
// layout is worked out again here from the protocol's description, independently of the
// decoder. Invariants: every request gets exactly one reply, with the request's op and seq;
// a malformed request (wrong length, trailing bytes, over a limit) is refused; a refused
// request changes nothing the client holds and carries no payload; an accepted one carries
// exactly the bytes the protocol says (read payloads, rx bytes, an ioctl value).
//
// Input: requests, each [u16 length][that many bytes], to the end; the length's top bit marks
// a request the server received truncated.
#include "drivers/protocol/sim_protocol.hpp"
#include "fuzz/byte_source.hpp"
#include "fuzz/check.hpp"
#include "sim/device_ops.hpp"
#include "sim/device_session.hpp"
#include "sim/sim_config.hpp"
#include "sim/sim_vehicle.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <linux/i2c.h>
#include <map>
#include <optional>
#include <vector>

using namespace caracara;
using namespace caracara::sim;
using caracara::fuzz::ByteSource;

namespace {

// The protocol's shape of a request, read without simproto::Reader.
struct Shape {
    bool well_formed = false;    // exact length, within the documented limits
    std::size_t reply_extra = 0; // payload bytes after the result when it succeeds
    int32_t handle = -1;
    uint64_t spi_bytes = 0;      // SpiMessage: the bytes of all its transfers
};

struct Cursor {
    std::span<const uint8_t> b;
    std::size_t at = 0;
    bool ok = true;
    uint64_t take(std::size_t n) {
        if (!ok || b.size() - at < n) {
            ok = false;
            return 0;
        }
        uint64_t v = 0;
        for (std::size_t i = 0; i < n; ++i)
            v |= uint64_t{b[at + i]} << (8 * i);
        at += n;
        return v;
    }
    void skip(std::size_t n) {
        if (!ok || b.size() - at < n)
            ok = false;
        else
            at += n;
    }
    bool str(std::size_t max) {
        const uint64_t n = take(4);
        if (n > max)
            ok = false;
        skip(static_cast<std::size_t>(n));
        return ok;
    }
};

Shape shape_of(uint16_t op, std::span<const uint8_t> req) {
    Shape s;
    Cursor c{req, 12};
    switch (static_cast<simproto::Op>(op)) {
    case simproto::Op::Open: c.str(4096); c.take(4); break;
    case simproto::Op::Close:
    case simproto::Op::GpioGet:
    case simproto::Op::GpioRelease: s.handle = int32_t(c.take(4)); break;
    case simproto::Op::GpioSet: s.handle = int32_t(c.take(4)); c.take(1); break;
    case simproto::Op::Ioctl: s.handle = int32_t(c.take(4)); c.take(8); c.take(8); s.reply_extra = 8; break;
    case simproto::Op::Write: {
        s.handle = int32_t(c.take(4));
        c.skip(static_cast<std::size_t>(c.take(4)));
        break;
    }
    case simproto::Op::GpioRequest: {
        c.str(256);
        c.str(256);
        c.take(4);
        const uint64_t mode = c.take(1);
        c.take(2);
        c.ok = c.ok && mode <= 3;
        break;
    }
    case simproto::Op::GpioWatch: c.str(256); c.str(256); c.take(4); break;
    case simproto::Op::I2cRdwr: {
        s.handle = int32_t(c.take(4));
        const uint64_t n = c.take(4);
        c.ok = c.ok && n >= 1 && n <= 42;  // I2C_RDWR_IOCTL_MAX_MSGS
        for (uint64_t i = 0; c.ok && i < n; ++i) {
            c.take(2);
            const uint64_t flags = c.take(2), len = c.take(2);
            c.ok = c.ok && len <= 8192;
            if (flags & I2C_M_RD)
                s.reply_extra += len;
            else
                c.skip(len);
        }
        break;
    }
    case simproto::Op::SpiMessage: {
        s.handle = int32_t(c.take(4));
        const uint64_t n = c.take(4);
        c.ok = c.ok && n <= 512;
        uint64_t total = 0;
        for (uint64_t i = 0; c.ok && i < n; ++i) {
            const uint64_t len = c.take(4);
            c.take(4 + 2 + 1 + 1);
            const bool tx = c.take(1) != 0, rx = c.take(1) != 0;
            total += len;
            s.spi_bytes = total;
            c.ok = c.ok && total <= 8192;
            if (tx)
                c.skip(len);
            if (rx)
                s.reply_extra += len;
        }
        break;
    }
    default: return s;  // GpioEvent and unknown ops: never well formed as a request
    }
    s.well_formed = c.ok && c.at == req.size();
    return s;
}

struct Held {
    std::map<int, std::pair<SimVehicle::NodeKind, std::string>> handles;
    std::map<int, int> gpio_lines;
    int watched = -1;
    int next = 0;
    bool operator==(const Held&) const = default;
};

Held held(const DeviceSession& s) {
    Held h;
    for (const auto& [k, v] : s.handles)
        h.handles[k] = {v.kind, v.path};
    h.gpio_lines = s.gpio_lines;
    h.watched = s.watched_line;
    h.next = s.next_handle;
    return h;
}

uint32_t le32(const uint8_t* p) { return uint32_t{p[0]} | uint32_t{p[1]} << 8 | uint32_t{p[2]} << 16 | uint32_t{p[3]} << 24; }

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    ByteSource in(data, size);
    SimVehicle vehicle(default_sim_config());
    DeviceOps ops(vehicle);
    DeviceSession session;
    static std::vector<uint8_t> reply(simproto::kMaxMessage);
    while (!in.empty()) {
        // The length's top bit: the server's recv() saw MSG_TRUNC (the request was longer than
        // kMaxMessage and only its start arrived).
        const uint16_t len = in.u16();
        const bool truncated = (len & 0x8000) != 0;
        const auto req = in.bytes(len & 0x7FFF);
        const Held before = held(session);
        const uint64_t bad_before = ops.bad_requests();
        uint64_t wire_ns = 1;
        const std::size_t n = ops.handle(session, req, reply, wire_ns, truncated);

        // Exactly one reply: the header echoes the request's op (as far as it could be read)
        // with the reply bit, and its seq.
        FUZZ_CHECK(n >= 16 && n <= reply.size(), "reply of %zu bytes", n);
        FUZZ_CHECK(le32(reply.data()) == simproto::kMagic, "reply without the magic");
        const uint16_t op = req.size() >= 6 ? uint16_t(req[4] | req[5] << 8) : 0;
        const uint32_t seq = req.size() >= 12 ? le32(req.data() + 8) : 0;
        const uint16_t reply_op = uint16_t(reply[4] | reply[5] << 8);
        FUZZ_CHECK(reply_op == ((op & ~simproto::kReplyBit) | simproto::kReplyBit) && reply[6] == 0 && reply[7] == 0,
                   "reply op %#x to op %#x", reply_op, op);
        FUZZ_CHECK(le32(reply.data() + 8) == seq, "reply seq %u to seq %u", le32(reply.data() + 8), seq);
        const int32_t result = int32_t(le32(reply.data() + 12));
        // CARACARA_FUZZ_TRACE=1: one line per request, to see what a seed reaches.
        static const bool trace = std::getenv("CARACARA_FUZZ_TRACE") != nullptr;
        if (trace)
            std::fprintf(stderr, "op %#x seq %u: %zu bytes -> result %d, %zu reply bytes\n", op, seq, req.size(), result,
                         n);

        const bool header_ok = req.size() >= 12 && le32(req.data()) == simproto::kMagic && !(op & simproto::kReplyBit);
        const Shape shape = header_ok && !truncated ? shape_of(op, req) : Shape{};
        if (truncated)
            FUZZ_CHECK(result == (header_ok ? -EMSGSIZE : -EBADMSG), "a truncated request answered %d", result);
        if (!shape.well_formed)
            FUZZ_CHECK(result < 0, "malformed request (op %#x, %zu bytes) answered %d", op, req.size(), result);
        if (result < 0) {
            // Refused: no payload, nothing the client holds has changed.
            FUZZ_CHECK(n == 16, "refusal %d with %zu payload bytes", result, n - 16);
            FUZZ_CHECK(held(session) == before, "refused op %#x changed the session", op);
            if (result == -EBADMSG)
                FUZZ_CHECK(ops.bad_requests() == bad_before + 1 && wire_ns == 0,
                           "a malformed request not counted, or it took the wire");
            continue;
        }
        FUZZ_CHECK(shape.well_formed, "accepted a malformed op %#x", op);
        FUZZ_CHECK(n == 16 + shape.reply_extra, "op %#x: %zu payload bytes, the protocol says %zu", op, n - 16,
                   shape.reply_extra);
        switch (static_cast<simproto::Op>(op)) {
        case simproto::Op::Open:
        case simproto::Op::GpioRequest: {
            // A new handle, never one in use.
            FUZZ_CHECK(result == before.next && !before.handles.count(result) && !before.gpio_lines.count(result),
                       "open gave handle %d", result);
            const Held after = held(session);
            FUZZ_CHECK(after.handles.count(result) + after.gpio_lines.count(result) == 1, "handle %d not held", result);
            break;
        }
        case simproto::Op::Close:
            FUZZ_CHECK(result == 0 && before.handles.count(shape.handle) && !session.handles.count(shape.handle),
                       "close of %d", shape.handle);
            break;
        case simproto::Op::GpioGet:
            FUZZ_CHECK(result == 0 || result == 1, "GPIO value %d", result);
            break;
        case simproto::Op::I2cRdwr:
            FUZZ_CHECK(result == int32_t(le32(req.data() + 16)), "I2C_RDWR: %d of %u messages", result,
                       le32(req.data() + 16));
            break;
        case simproto::Op::SpiMessage:
            FUZZ_CHECK(uint64_t(result) == shape.spi_bytes, "SPI message: %d of %llu bytes", result,
                       (unsigned long long)shape.spi_bytes);
            break;
        default: break;
        }
    }
    ops.release(session);
    return 0;
}
