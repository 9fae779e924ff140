// The socket protocol between SimDeviceIo (in caracarad) and caracara-sim.
//
// One SOCK_SEQPACKET message per request and per reply, little-endian. The request carries
// exactly what the kernel would read from the caller's ioctl argument (the i2c_msg array
// with the write payloads, the spi_ioc_transfer array with tx buffers, the value of a
// value ioctl); the reply carries the result (>= 0 or -errno) and exactly what the kernel
// would write back (read payloads, rx buffers, the value of a read ioctl).
//
//   header   u32 magic 'CSIM', u16 op, u16 reserved(0), u32 seq
//   request  Open        str path, i32 flags
//            Close       i32 handle
//            I2cRdwr     i32 handle, u32 n, n x { u16 addr, u16 flags, u16 len, [len bytes if write] }
//            SpiMessage  i32 handle, u32 n, n x { u32 len, u32 speed_hz, u16 delay_usecs,
//                                                  u8 bits_per_word, u8 cs_change, u8 has_tx, u8 has_rx,
//                                                  [len bytes if has_tx] }
//            Ioctl       i32 handle, u64 request, u64 value-in     (value and small pointer ioctls)
//            Write       i32 handle, u32 n, n bytes                (sysfs attributes: bind/unbind)
//            GpioRequest str chip, str name, i32 offset (-1: by name), u8 mode, u8 active_low, u8 initial
//            GpioGet     i32 line;   GpioSet  i32 line, u8 value;   GpioRelease i32 line
//            GpioWatch   str chip, str name, i32 offset (on a connection of its own: from then on the simulator only
//                                      pushes GpioEvent messages there: header op GpioEvent|reply,
//                                      seq 0, i32 new logical value, u64 CLOCK_MONOTONIC ns of the
//                                      change, the stamp of the simulator's "gpio" wire-log entry)
//   reply    header with op | 0x8000 and the request's seq, i32 result, then
//            I2cRdwr: the bytes of every read message in order; SpiMessage: the rx bytes of every
//            transfer with has_rx in order; Ioctl: u64 value-out; others: nothing.
// A malformed request gets a reply with -EBADMSG (or -ENOTTY for an unknown ioctl), never a crash.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string_view>

namespace caracara::simproto {

inline constexpr uint32_t kMagic = 0x4d495343; // "CSIM"
inline constexpr size_t kMaxMessage = 65536;
inline constexpr uint16_t kReplyBit = 0x8000;

enum class Op : uint16_t {
    Open = 1,
    Close = 2,
    I2cRdwr = 3,
    SpiMessage = 4,
    Ioctl = 5,
    Write = 6,
    GpioRequest = 7,
    GpioGet = 8,
    GpioSet = 9,
    GpioRelease = 10,
    GpioWatch = 11,
    GpioEvent = 12,
};

// GPIO request modes on the wire (drivers/platform/sim/ maps GpioLine's modes to these).
enum class GpioMode : uint8_t {
    Input = 0,
    InputEdges = 1, // input with both-edge events
    Output = 2,     // push-pull
    OpenDrain = 3,  // drives low or releases; reading returns the wire
};

struct Header {
    uint32_t magic = kMagic;
    uint16_t op = 0;
    uint16_t reserved = 0;
    uint32_t seq = 0;
};
inline constexpr size_t kHeaderSize = 12;

// Bounds-checked little-endian writer over a caller-owned buffer (no allocation).
class Writer {
public:
    explicit Writer(std::span<uint8_t> buf) : buf_(buf) {}
    void u8(uint8_t v) { put(&v, 1); }
    void u16(uint16_t v) { uint8_t b[2] = {uint8_t(v), uint8_t(v >> 8)}; put(b, 2); }
    void u32(uint32_t v) { uint8_t b[4]; for (int i = 0; i < 4; ++i) b[i] = uint8_t(v >> (8 * i)); put(b, 4); }
    void u64(uint64_t v) { uint8_t b[8]; for (int i = 0; i < 8; ++i) b[i] = uint8_t(v >> (8 * i)); put(b, 8); }
    void i32(int32_t v) { u32(static_cast<uint32_t>(v)); }
    void bytes(const void* p, size_t n) { put(p, n); }
    void str(std::string_view s) { u32(static_cast<uint32_t>(s.size())); put(s.data(), s.size()); }
    void header(Op op, uint32_t seq, bool reply = false) {
        u32(kMagic); u16(static_cast<uint16_t>(static_cast<uint16_t>(op) | (reply ? kReplyBit : 0))); u16(0); u32(seq);
    }
    bool ok() const { return ok_; }
    size_t size() const { return pos_; }
    uint8_t* data() { return buf_.data(); }
    // Reserve n bytes to be filled in later (e.g. read payloads); returns nullptr on overflow.
    uint8_t* reserve(size_t n) {
        if (!ok_ || buf_.size() - pos_ < n) { ok_ = false; return nullptr; }
        uint8_t* p = buf_.data() + pos_; pos_ += n; return p;
    }

private:
    void put(const void* p, size_t n) {
        if (!ok_ || buf_.size() - pos_ < n) { ok_ = false; return; }
        if (n) std::memcpy(buf_.data() + pos_, p, n);
        pos_ += n;
    }
    std::span<uint8_t> buf_;
    size_t pos_ = 0;
    bool ok_ = true;
};

// Bounds-checked little-endian reader; any overrun sets !ok() and returns zeros.
class Reader {
public:
    explicit Reader(std::span<const uint8_t> buf) : buf_(buf) {}
    uint8_t u8() { uint8_t b[1] = {0}; get(b, 1); return b[0]; }
    uint16_t u16() { uint8_t b[2] = {0, 0}; get(b, 2); return uint16_t(b[0] | (b[1] << 8)); }
    uint32_t u32() { uint8_t b[4] = {}; get(b, 4); uint32_t v = 0; for (int i = 3; i >= 0; --i) v = (v << 8) | b[i]; return v; }
    uint64_t u64() { uint8_t b[8] = {}; get(b, 8); uint64_t v = 0; for (int i = 7; i >= 0; --i) v = (v << 8) | b[i]; return v; }
    int32_t i32() { return static_cast<int32_t>(u32()); }
    // Returns a view into the buffer; empty and !ok() on overrun.
    std::span<const uint8_t> bytes(size_t n) {
        if (!ok_ || buf_.size() - pos_ < n) { ok_ = false; return {}; }
        auto s = buf_.subspan(pos_, n); pos_ += n; return s;
    }
    std::string_view str(size_t max_len) {
        uint32_t n = u32();
        if (n > max_len) { ok_ = false; return {}; }
        auto b = bytes(n);
        return {reinterpret_cast<const char*>(b.data()), b.size()};
    }
    bool header(Header& h) {
        h.magic = u32(); h.op = u16(); h.reserved = u16(); h.seq = u32();
        return ok_ && h.magic == kMagic;
    }
    bool ok() const { return ok_; }
    bool at_end() const { return pos_ == buf_.size(); }
    size_t remaining() const { return buf_.size() - pos_; }

private:
    void get(void* p, size_t n) {
        if (!ok_ || buf_.size() - pos_ < n) { ok_ = false; return; }
        std::memcpy(p, buf_.data() + pos_, n);
        pos_ += n;
    }
    std::span<const uint8_t> buf_;
    size_t pos_ = 0;
    bool ok_ = true;
};

// How a non-transfer ioctl moves its argument; the sim and the client agree on this table.
enum class ArgKind { Unknown, Value, PtrIn, PtrOut };
struct IoctlArg {
    ArgKind kind = ArgKind::Unknown;
    size_t size = 0; // bytes behind the pointer for PtrIn/PtrOut
};
IoctlArg classify_ioctl(unsigned long request);

} // namespace caracara::simproto
