// Appends little-endian integers, floats and length-prefixed strings to a byte vector (the
// dive file's encoding), or to a FixedBytes on the stack for a record of bounded size.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <string_view>
#include <vector>

namespace caracara {

template <typename Out>
class BasicByteWriter {
public:
    explicit BasicByteWriter(Out& out) : out_(out) {}
    void u8(uint8_t v) { out_.push_back(v); }
    void u16(uint16_t v) { le(v, 2); }
    void u32(uint32_t v) { le(v, 4); }
    void u64(uint64_t v) { le(v, 8); }
    void i16(int16_t v) { u16(static_cast<uint16_t>(v)); }
    void f32(float v) { u32(std::bit_cast<uint32_t>(v)); }
    // u16 length, then the bytes; cut at `max` bytes.
    void str(std::string_view s, std::size_t max) {
        if (s.size() > max)
            s = s.substr(0, max);
        u16(static_cast<uint16_t>(s.size()));
        out_.insert(out_.end(), s.begin(), s.end());
    }
    void raw(std::string_view s) { out_.insert(out_.end(), s.begin(), s.end()); }
    std::size_t size() const { return out_.size(); }
    // Overwrites a u16 written earlier at `at` (a record's length, once its body is known).
    void patch_u16(std::size_t at, uint16_t v) {
        out_[at] = static_cast<uint8_t>(v);
        out_[at + 1] = static_cast<uint8_t>(v >> 8);
    }

private:
    void le(uint64_t v, int n) {
        if constexpr (requires(const uint8_t* b) { out_.append(b, std::size_t{}); }) {
            uint8_t b[8];
            for (int i = 0; i < n; ++i)
                b[i] = static_cast<uint8_t>(v >> (8 * i));
            out_.append(b, static_cast<std::size_t>(n));
        } else {
            for (int i = 0; i < n; ++i)
                out_.push_back(static_cast<uint8_t>(v >> (8 * i)));
        }
    }
    Out& out_;
};

using ByteWriter = BasicByteWriter<std::vector<uint8_t>>;

} // namespace caracara
