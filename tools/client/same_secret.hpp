// Compares a secret a client brought with the real one in a time that does not depend on where
// the first difference is (the bridge's token, caracaractl bridge's key).
#pragma once

#include <string_view>

namespace caracara::client {

inline bool same_secret(std::string_view a, std::string_view b) {
    if (a.size() != b.size())
        return false;
    unsigned char diff = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        diff |= static_cast<unsigned char>(a[i] ^ b[i]);
    return diff == 0;
}

} // namespace caracara::client
