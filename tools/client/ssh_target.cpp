#include "tools/client/ssh_target.hpp"

#include <algorithm>
#include <cctype>

namespace caracara::client {

namespace {

bool valid_port(std::string_view p) {
    if (p.empty() || p.size() > 5 || !std::all_of(p.begin(), p.end(), [](char c) { return c >= '0' && c <= '9'; }))
        return false;
    const int n = std::stoi(std::string(p));
    return n >= 1 && n <= 65535;
}

bool valid_name(std::string_view s) {
    return !s.empty() && s.front() != '-' &&
           std::none_of(s.begin(), s.end(), [](char c) { return std::isspace(static_cast<unsigned char>(c)) || c == '/' || c == '@' || c == '[' || c == ']'; });
}

} // namespace

std::optional<SshTarget> parse_ssh_target(std::string_view value) {
    SshTarget t;
    if (value.empty() || value.front() == '-')
        return std::nullopt;
    if (const auto at = value.find('@'); at != std::string_view::npos) {
        t.user = std::string(value.substr(0, at));
        if (!valid_name(t.user))
            return std::nullopt;
        value.remove_prefix(at + 1);
    }
    std::string_view rest;
    if (!value.empty() && value.front() == '[') {
        const auto close = value.find(']');
        if (close == std::string_view::npos || close == 1)
            return std::nullopt;
        t.host = std::string(value.substr(1, close - 1));
        if (!std::all_of(t.host.begin(), t.host.end(), [](char c) { return std::isxdigit(static_cast<unsigned char>(c)) || c == ':' || c == '.' || c == '%'; }))
            return std::nullopt;
        rest = value.substr(close + 1);
        if (!rest.empty() && rest.front() != ':')
            return std::nullopt;
    } else {
        const auto colon = value.find(':');
        t.host = std::string(value.substr(0, colon));
        if (!valid_name(t.host))
            return std::nullopt;
        rest = colon == std::string_view::npos ? std::string_view{} : value.substr(colon);
    }
    if (!rest.empty()) {
        rest.remove_prefix(1); // ':'
        if (!valid_port(rest))
            return std::nullopt; // HOST:CONTAINER is not taken: a port is a number
        t.port = std::string(rest);
    }
    return t;
}

} // namespace caracara::client
