// What caracara-ros's publishers share to read the mirrored objects and stamp what they write:
// a property by name, the thrusters' object paths, a message header at the time of a reading.
#pragma once

#include "tools/client/client.hpp"

#include <ctime>
#include <ros_msgs.h>
#include <string>

namespace caracara::ros {

inline const std::string kThrusterPathPrefix = std::string(caracara::dbus::kRootPath) + "/thruster/";

// The property `name` of `p`, or an empty Value when the object has none (yet).
inline const client::Value& prop(const client::Props& p, const char* name) {
    static const client::Value none;
    const auto it = p.find(name);
    return it == p.end() ? none : it->second;
}

// The generated messages' strings are char*; DDS only reads them during the write.
inline char* msg_str(const std::string& s) { return const_cast<char*>(s.c_str()); }

inline timespec realtime_now() {
    timespec t{};
    clock_gettime(CLOCK_REALTIME, &t);
    return t;
}

// The header's frame_id points into `frame`, which must outlive the message's write. `at`: the
// time of the reading the message carries (now for what has no reading: diagnostics, state).
inline std_msgs_msg_dds__Header_ header(const std::string& frame, const timespec& at = realtime_now()) {
    return {{static_cast<int32_t>(at.tv_sec), static_cast<uint32_t>(at.tv_nsec)}, msg_str(frame)};
}

} // namespace caracara::ros
