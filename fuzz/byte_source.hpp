// The fuzz input read front to back as the harness's choices. Past the end every read gives
// zeros, so any input is a complete run and the seed generator (make_seeds.py) can write the
// same layout byte by byte.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace caracara::fuzz {

class ByteSource {
public:
    ByteSource(const uint8_t* data, std::size_t size) : data_(data, size) {}
    explicit ByteSource(std::span<const uint8_t> data) : data_(data) {}

    bool empty() const { return pos_ >= data_.size(); }
    std::size_t remaining() const { return empty() ? 0 : data_.size() - pos_; }
    uint8_t u8() { return empty() ? 0 : data_[pos_++]; }
    uint16_t u16() { const uint16_t lo = u8(); return static_cast<uint16_t>(lo | u8() << 8); }
    uint32_t u32() { const uint32_t lo = u16(); return lo | static_cast<uint32_t>(u16()) << 16; }
    uint64_t u64() { const uint64_t lo = u32(); return lo | static_cast<uint64_t>(u32()) << 32; }
    int16_t i16() { return static_cast<int16_t>(u16()); }
    int32_t i32() { return static_cast<int32_t>(u32()); }
    // Up to n bytes (fewer at the end of the input).
    std::span<const uint8_t> bytes(std::size_t n) {
        const std::size_t k = n < remaining() ? n : remaining();
        const auto s = data_.subspan(pos_, k);
        pos_ += k;
        return s;
    }
    std::span<const uint8_t> rest() { return bytes(remaining()); }

private:
    std::span<const uint8_t> data_;
    std::size_t pos_ = 0;
};

} // namespace caracara::fuzz
