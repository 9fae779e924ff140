#include "tools/foxglove/cdr_writer.hpp"

#include <bit>
#include <cstring>

namespace caracara::foxglove {

static_assert(std::endian::native == std::endian::little, "CDR_LE is written as the machine holds it");

void CdrWriter::put(const void* p, std::size_t size) {
    // Alignment counts from the end of the encapsulation header.
    while ((out_.size() - 4) % size != 0)
        out_.push_back(0);
    const auto* b = static_cast<const uint8_t*>(p);
    out_.insert(out_.end(), b, b + size);
}

void CdrWriter::string(std::string_view s) {
    u32(static_cast<uint32_t>(s.size() + 1));
    out_.insert(out_.end(), s.begin(), s.end());
    out_.push_back(0);
}

void CdrWriter::header(uint64_t time_ns, std::string_view frame_id) {
    i32(static_cast<int32_t>(time_ns / 1'000'000'000u));
    u32(static_cast<uint32_t>(time_ns % 1'000'000'000u));
    string(frame_id);
}

} // namespace caracara::foxglove
