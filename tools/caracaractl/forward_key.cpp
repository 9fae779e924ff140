#include "tools/caracaractl/forward_key.hpp"

#include "tools/client/client.hpp"
#include "tools/client/same_secret.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <optional>
#include <strings.h>
#include <sys/random.h>

namespace caracara::ctl {

namespace {

constexpr std::string_view kKeyParam = "key";

bool iequals(std::string_view a, std::string_view b) {
    return a.size() == b.size() && ::strncasecmp(a.data(), b.data(), a.size()) == 0;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
        s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
        s.remove_suffix(1);
    return s;
}

// Calls f(item) for each item of s separated by sep.
template <typename F> void each(std::string_view s, char sep, F f) {
    std::size_t at = 0;
    while (at <= s.size()) {
        const auto end = s.find(sep, at);
        f(s.substr(at, end == std::string_view::npos ? std::string_view::npos : end - at));
        if (end == std::string_view::npos)
            break;
        at = end + 1;
    }
}

// The value of one name=value item when it is `name`'s; nullopt otherwise.
std::optional<std::string_view> item_value(std::string_view item, std::string_view name) {
    item = trim(item);
    if (item.size() > name.size() && item.starts_with(name) && item[name.size()] == '=')
        return item.substr(name.size() + 1);
    return std::nullopt;
}

// name=value in a list of them ("a=1&key=K", "x=1; caracara_key_8765=K"); nullopt when absent.
std::optional<std::string_view> value_of(std::string_view list, char sep, std::string_view name) {
    std::optional<std::string_view> found;
    each(list, sep, [&](std::string_view item) {
        if (const auto v = item_value(item, name))
            found = v;
    });
    return found;
}

bool is_control(char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; }

// The client's bytes as a log shows them: a control byte as '?', so that a header cannot forge a line.
std::string printable(std::string_view s) {
    std::string out(s);
    std::replace_if(out.begin(), out.end(), is_control, '?');
    return out;
}

std::string response(const char* status, const std::string& headers, const std::string& body) {
    return std::string("HTTP/1.1 ") + status + "\r\nServer: caracaractl\r\nCache-Control: no-store\r\n" + headers +
           "Content-Type: text/plain; charset=utf-8\r\nContent-Length: " + std::to_string(body.size()) +
           "\r\nConnection: close\r\n\r\n" + body;
}

} // namespace

ForwardKey ForwardKey::random(uint16_t port) {
    unsigned char bytes[32];
    if (::getrandom(bytes, sizeof bytes, 0) != static_cast<ssize_t>(sizeof bytes))
        throw client::Failure{client::kExitUnavailable, std::string("getrandom: ") + std::strerror(errno)};
    static constexpr char kHex[] = "0123456789abcdef";
    std::string key;
    for (const unsigned char b : bytes)
        key += {kHex[b >> 4], kHex[b & 15]};
    return ForwardKey(key, port);
}

ForwardKey::Judgement ForwardKey::judge(std::string_view head) const {
    Judgement j{Verdict::BadRequest, "", ""};
    const auto line_end = head.find("\r\n");
    const std::string_view line = head.substr(0, line_end);
    const auto sp1 = line.find(' '), sp2 = line.rfind(' ');
    if (line_end == std::string_view::npos || sp1 == std::string_view::npos || sp2 <= sp1 ||
        !line.substr(sp2 + 1).starts_with("HTTP/1."))
        return j;
    const std::string_view target = line.substr(sp1 + 1, sp2 - sp1 - 1);
    // No control byte in the request line: the target goes back out in a redirect's Location,
    // where a line break would add headers of the client's choosing (fuzz_bridge_http found it).
    // No space in the target either (RFC 9112 3.2): "/? key=K" would find the key and leave it
    // in the Location (fuzz_bridge_http again).
    if (!target.starts_with('/') || std::any_of(line.begin(), line.end(), is_control) ||
        target.find(' ') != std::string_view::npos)
        return j;
    bool upgrade = false;
    std::optional<std::string_view> cookie;
    each(head.substr(line_end + 2), '\n', [&](std::string_view h) {
        const auto colon = h.find(':');
        if (colon == std::string_view::npos)
            return;
        const std::string_view name = h.substr(0, colon), value = trim(h.substr(colon + 1));
        if (iequals(name, "upgrade"))
            upgrade = upgrade || iequals(value, "websocket");
        else if (iequals(name, "cookie"))
            cookie = cookie ? cookie : value_of(value, ';', cookie_name());
        else if (iequals(name, "origin"))
            j.origin = printable(value.substr(0, 200));
    });
    const auto q = target.find('?');
    const std::string_view path = target.substr(0, q), query = q == std::string_view::npos ? "" : target.substr(q + 1);
    if (const auto in_query = value_of(query, '&', kKeyParam)) {
        if (!client::same_secret(*in_query, key_)) {
            j.verdict = Verdict::WrongKey;
        } else if (upgrade) {
            j.verdict = Verdict::Relay;
        } else {
            // The same address without the key: it leaves the address bar and the page's own URL.
            // Nor any other item holding it ("?key=K&K"): the Location stays in the browser's
            // history (fuzz_bridge_http found it).
            std::string rest;
            each(query, '&', [&](std::string_view item) {
                if (!item.empty() && !item_value(item, kKeyParam) && item.find(key_) == std::string_view::npos)
                    rest += (rest.empty() ? "" : "&") + std::string(item);
            });
            j.verdict = Verdict::Redirect;
            j.location = std::string(path) + (rest.empty() ? "" : "?" + rest);
        }
    } else if (cookie) {
        j.verdict = client::same_secret(*cookie, key_) ? Verdict::Relay : Verdict::WrongKey;
    } else {
        j.verdict = Verdict::NoKey;
    }
    return j;
}

std::string ForwardKey::answer(const Judgement& j) const {
    const std::string where = "open the address `caracaractl bridge` printed (http://localhost:" +
                              std::to_string(port_) + "/?key=..., or ws://localhost:" + std::to_string(port_) +
                              "/?key=... in Foxglove)\n";
    switch (j.verdict) {
    case Verdict::Redirect:
        // Strict: sent only with requests from this site's own pages; HttpOnly: not to scripts.
        return response("303 See Other", "Location: " + j.location + "\r\nSet-Cookie: " + cookie_name() + "=" + key_ +
                                             "; Path=/; HttpOnly; SameSite=Strict\r\nReferrer-Policy: no-referrer\r\n",
                        "");
    case Verdict::NoKey:
        return response("403 Forbidden", "", "caracaractl: this forward needs the key of its session: " + where);
    case Verdict::WrongKey:
        return response("403 Forbidden", "", "caracaractl: wrong key for this forward (an earlier session's?): " + where);
    case Verdict::BadRequest:
    case Verdict::Relay:
        break;
    }
    return response("400 Bad Request", "", "caracaractl: not an HTTP request\n");
}

} // namespace caracara::ctl
