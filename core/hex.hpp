// "0x52": addresses in messages, written one way everywhere.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

namespace caracara {

inline std::string hex(int64_t v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "0x%02llX", static_cast<unsigned long long>(v));
    return buf;
}

} // namespace caracara
