// A DDS GUID as ROS 2 prints a GID (rclpy's TopicEndpointInfo: each byte as two hex digits,
// dotted), zero-padded to the distro's Gid: Humble's 24 bytes, 16 since Iron. How caracara-ros's
// journal and /diagnostics name a writer or reader of another participant.
#pragma once

#include "tools/ros/ros_conventions.hpp"

#include <cstdio>
#include <dds/dds.h>
#include <string>

namespace caracara::ros {

inline std::string gid_text(const dds_guid_t& g, RangeLayout distro) {
    std::string s;
    char b[4];
    const std::size_t size = distro == RangeLayout::Humble ? 24 : 16;
    for (std::size_t i = 0; i < size; ++i) {
        std::snprintf(b, sizeof b, "%02x", i < sizeof g.v ? g.v[i] : 0u);
        s += (i ? "." : "") + std::string(b);
    }
    return s;
}

} // namespace caracara::ros
