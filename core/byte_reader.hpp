// Reads little-endian values from a byte span without ever reading past its end: a short
// read sets failed() and returns zero, so a decoder checks once, after a whole record.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

namespace caracara {

class ByteReader {
public:
    explicit ByteReader(std::span<const uint8_t> bytes) : b_(bytes) {}
    uint8_t u8() { return static_cast<uint8_t>(le(1)); }
    uint16_t u16() { return static_cast<uint16_t>(le(2)); }
    uint32_t u32() { return static_cast<uint32_t>(le(4)); }
    uint64_t u64() { return le(8); }
    int16_t i16() { return static_cast<int16_t>(u16()); }
    float f32() { return std::bit_cast<float>(u32()); }
    std::string str(std::size_t max) {
        const std::size_t n = u16();
        if (n > max || !take(n))
            return fail(), std::string();
        return std::string(reinterpret_cast<const char*>(b_.data() + pos_ - n), n);
    }
    // Skips `n` bytes; false (and failed) when fewer are left.
    bool take(std::size_t n) {
        if (failed_ || n > left())
            return fail(), false;
        pos_ += n;
        return true;
    }
    std::size_t pos() const { return pos_; }
    std::size_t left() const { return b_.size() - pos_; }
    bool failed() const { return failed_; }
    void fail() { failed_ = true; }

private:
    uint64_t le(int n) {
        if (!take(static_cast<std::size_t>(n)))
            return 0;
        uint64_t v = 0;
        for (int i = 0; i < n; ++i)
            v |= static_cast<uint64_t>(b_[pos_ - n + i]) << (8 * i);
        return v;
    }
    std::span<const uint8_t> b_;
    std::size_t pos_ = 0;
    bool failed_ = false;
};

} // namespace caracara
