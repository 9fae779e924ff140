// Plain CDR (XCDR1, little-endian) as ROS 2 messages travel and rosbag2 stores them: the 4-byte
// encapsulation header (CDR_LE), then each primitive aligned to its size counted from after the
// header, strings as a length with the NUL and the bytes, sequences as a count then the items.
// For caracaractl's dive export (no DDS library in the base package).
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

namespace caracara::foxglove {

class CdrWriter {
public:
    CdrWriter() : out_{0x00, 0x01, 0x00, 0x00} {}

    void u8(uint8_t v) { put(&v, 1); }
    void boolean(bool v) { u8(v ? 1 : 0); }
    void i32(int32_t v) { put(&v, 4); }
    void u32(uint32_t v) { put(&v, 4); }
    void f32(float v) { put(&v, 4); }
    void f64(double v) { put(&v, 8); }
    void string(std::string_view s);
    // ROS 2's builtin_interfaces/Time and std_msgs/Header.
    void header(uint64_t time_ns, std::string_view frame_id);

    const std::vector<uint8_t>& bytes() const { return out_; }

private:
    void put(const void* p, std::size_t size);

    std::vector<uint8_t> out_;
};

} // namespace caracara::foxglove
