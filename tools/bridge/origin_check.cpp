#include "tools/bridge/origin_check.hpp"

#include <algorithm>
#include <cctype>

namespace caracara::bridge {

namespace {

std::string lower(std::string_view s) {
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return out;
}

bool all_of(std::string_view s, const char* chars) {
    return !s.empty() && s.find_first_not_of(chars) == std::string_view::npos;
}

constexpr const char* kDigits = "0123456789";

// A Host header's name is safe from DNS rebinding when no resolver is asked: localhost (which
// browsers resolve themselves), an IPv4 address, or an IPv6 address in brackets.
bool rebinding_proof(std::string_view host) {
    if (host.starts_with('['))
        return host.find(']') != std::string_view::npos;
    const std::string_view name = host.substr(0, host.find(':'));
    return name == "localhost" || all_of(name, ".0123456789");
}

} // namespace

OriginCheck::OriginCheck(const std::vector<std::string>& allowed, bool token) : token_(token) {
    for (const std::string& a : allowed)
        if (auto n = normalize(a))
            allowed_.push_back(*n);
}

std::optional<std::string> OriginCheck::normalize(std::string_view origin) {
    const std::string o = lower(origin);
    const auto sep = o.find("://");
    if (sep == std::string::npos)
        return std::nullopt;
    const std::string scheme = o.substr(0, sep);
    std::string host = o.substr(sep + 3), port;
    if (!all_of(scheme, "abcdefghijklmnopqrstuvwxyz0123456789+-.") || !std::isalpha(static_cast<unsigned char>(scheme[0])))
        return std::nullopt;
    const auto bracket = host.find(']');
    const auto colon = host.find(':', host.starts_with('[') && bracket != std::string::npos ? bracket : 0);
    if (colon != std::string::npos) {
        port = host.substr(colon + 1);
        host.resize(colon);
        if (!all_of(port, kDigits) || port.size() > 5 || std::stoul(port) == 0 || std::stoul(port) > 65535)
            return std::nullopt;
        port = std::to_string(std::stoul(port)); // no leading zeros, as a browser sends it
    }
    const bool ipv6 = host.starts_with('[') && host.ends_with(']') && all_of(host.substr(1, host.size() - 2), "0123456789abcdef:.");
    if (!ipv6 && !all_of(host, "abcdefghijklmnopqrstuvwxyz0123456789-."))
        return std::nullopt;
    if ((scheme == "http" && port == "80") || (scheme == "https" && port == "443"))
        port.clear();
    return scheme + "://" + host + (port.empty() ? "" : ":" + port);
}

OriginCheck::Verdict OriginCheck::judge(std::optional<std::string_view> origin, std::string_view host) const {
    if (!origin)
        return Verdict::NoOrigin;
    const std::string o = lower(*origin);
    if (std::find(allowed_.begin(), allowed_.end(), o) != allowed_.end())
        return Verdict::Allowed;
    if (host.empty() || o != "http://" + lower(host))
        return Verdict::Foreign;
    return token_ || rebinding_proof(lower(host)) ? Verdict::Own : Verdict::Rebindable;
}

} // namespace caracara::bridge
