// A byte buffer of fixed capacity with the few operations of a std::vector<uint8_t> that
// ByteWriter uses: a record whose largest size is known is written here, on the stack, without
// a capacity check and a possible allocation per byte, then appended to its vector at once.
// Bytes past the capacity are dropped and counted as lost (overflowed()): a writer's size is
// checked against its format's bound, not trusted.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace caracara {

template <std::size_t N>
class FixedBytes {
public:
    using value_type = uint8_t;

    void push_back(uint8_t b) {
        if (size_ < N)
            bytes_[size_++] = b;
        else
            overflowed_ = true;
    }
    template <typename It>
    void insert(const uint8_t* /*end()*/, It first, It last) {
        for (; first != last; ++first)
            push_back(static_cast<uint8_t>(*first));
    }
    // `n` bytes at once (a little-endian field: one bounds check, one copy).
    void append(const uint8_t* b, std::size_t n) {
        if (n > N - size_) {
            overflowed_ = true;
            return;
        }
        std::memcpy(bytes_.data() + size_, b, n);
        size_ += n;
    }
    std::size_t size() const { return size_; }
    bool overflowed() const { return overflowed_; }
    uint8_t& operator[](std::size_t i) { return bytes_[i]; }
    const uint8_t* begin() const { return bytes_.data(); }
    const uint8_t* end() const { return bytes_.data() + size_; }

private:
    std::array<uint8_t, N> bytes_;
    std::size_t size_ = 0;
    bool overflowed_ = false;
};

} // namespace caracara
