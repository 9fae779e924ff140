// Who may reach the vehicle through a web page (issue 46), fed arbitrary requests: the bridge's
// Origin rules (tools/bridge/origin_check.hpp) and the key of a `caracaractl bridge` forward
// (tools/caracaractl/forward_key.hpp). Invariants: a request is relayed only when it carries this
// session's key; a redirect never carries the key in its address, and no answer carries a byte
// of the request that could split its header; an origin is taken only when it is none, the
// bridge's own (exactly http:// and the request's Host) or on the allow-list, and normalizing is
// stable; the verdict for no Origin is always "not a browser page".
#include "fuzz/byte_source.hpp"
#include "fuzz/check.hpp"
#include "tools/bridge/origin_check.hpp"
#include "tools/caracaractl/forward_key.hpp"

#include <algorithm>
#include <cctype>
#include <string>
#include <string_view>
#include <vector>

using namespace caracara;

namespace {

const std::string kKey(64, 'a'); // a session's key: 32 bytes as hex, as ForwardKey::random makes them
constexpr uint16_t kPort = 8765;

std::string text(fuzz::ByteSource& in, std::size_t max) {
    const auto b = in.bytes(in.u8() % (max + 1));
    return std::string(b.begin(), b.end());
}

void forward_key(fuzz::ByteSource& in) {
    const ctl::ForwardKey key(kKey, kPort);
    std::string head = text(in, 255);
    // Splice in the key, a near miss of it, or the cookie, where the input says, so that the
    // relayed paths are reached.
    const uint8_t how = in.u8();
    std::string piece = how & 1 ? kKey : kKey.substr(0, kKey.size() - 1) + "b";
    if (how & 2)
        piece = key.cookie_name() + "=" + piece;
    else
        piece = "key=" + piece;
    head.insert(std::min<std::size_t>(in.u8(), head.size()), piece);
    head += text(in, 64) + "\r\n\r\n";
    const ctl::ForwardKey::Judgement j = key.judge(head);
    using V = ctl::ForwardKey::Verdict;
    if (j.verdict == V::Relay || j.verdict == V::Redirect)
        FUZZ_CHECK(head.find(kKey) != std::string::npos, "relayed without the key: %s", head.c_str());
    if (j.verdict == V::Relay)
        return;
    if (j.verdict == V::Redirect) {
        FUZZ_CHECK(j.location.find(kKey) == std::string::npos, "the redirect carries the key: %s", j.location.c_str());
        FUZZ_CHECK(j.location.starts_with('/'), "redirect to %s", j.location.c_str());
    }
    for (const std::string* s : {&j.location, &j.origin})
        FUZZ_CHECK(s->find_first_of("\r\n") == std::string::npos, "a line break from the request: %s", s->c_str());
    const std::string answer = key.answer(j);
    FUZZ_CHECK(answer.starts_with("HTTP/1.1 "), "answer %s", answer.c_str());
    const auto end = answer.find("\r\n\r\n");
    FUZZ_CHECK(end != std::string::npos, "an answer without its blank line");
    // The head of the answer: after the status line, each line a header of ours.
    static const std::string_view kOurs[] = {"Server:", "Cache-Control:", "Location:", "Set-Cookie:", "Content-Type:",
                                             "Content-Length:", "Connection:", "Referrer-Policy:"};
    for (std::size_t at = answer.find("\r\n") + 2; at < end; at = answer.find("\r\n", at) + 2) {
        const std::string_view line(answer.data() + at, answer.find("\r\n", at) - at);
        FUZZ_CHECK(std::any_of(std::begin(kOurs), std::end(kOurs), [&](std::string_view h) { return line.starts_with(h); }),
                   "a header line not ours: %.*s", static_cast<int>(line.size()), line.data());
    }
    const char* status = j.verdict == V::Redirect ? "HTTP/1.1 303" : j.verdict == V::BadRequest ? "HTTP/1.1 400"
                                                                                                : "HTTP/1.1 403";
    FUZZ_CHECK(answer.starts_with(status), "verdict %d answered %s", static_cast<int>(j.verdict), answer.c_str());
}

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
    return s;
}

void origin_check(fuzz::ByteSource& in) {
    std::vector<std::string> allowed;
    for (int n = in.u8() % 3; n > 0; --n)
        if (auto a = bridge::OriginCheck::normalize(text(in, 40)))
            allowed.push_back(*a);
    const bool token = in.u8() & 1;
    const bridge::OriginCheck check(allowed, token);
    const std::string host = text(in, 40);
    const bool has_origin = in.u8() & 1;
    const std::string origin = text(in, 80);

    FUZZ_CHECK(check.judge(std::nullopt, host) == bridge::OriginCheck::Verdict::NoOrigin, "no Origin not taken");
    if (const auto n = bridge::OriginCheck::normalize(origin)) {
        FUZZ_CHECK(bridge::OriginCheck::normalize(*n) == *n, "normalize(%s) = %s is not stable", origin.c_str(), n->c_str());
        FUZZ_CHECK(lower(*n) == *n && n->find('/', n->find("://") + 3) == std::string::npos, "normalized %s", n->c_str());
    }
    if (!has_origin)
        return;
    const auto v = check.judge(std::string_view(origin), host);
    using V = bridge::OriginCheck::Verdict;
    FUZZ_CHECK(v != V::NoOrigin, "an Origin header judged as none");
    const auto n = bridge::OriginCheck::normalize(origin);
    if (v == V::Allowed)
        FUZZ_CHECK(n && std::find(allowed.begin(), allowed.end(), *n) != allowed.end(), "%s taken off the list",
                   origin.c_str());
    if (v == V::Own)
        FUZZ_CHECK(!host.empty() && lower(origin) == "http://" + lower(host), "%s taken as the bridge's own (Host %s)",
                   origin.c_str(), host.c_str());
    FUZZ_CHECK(check.refused(v) == (v == V::Foreign || v == V::Rebindable), "refused()");
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
    fuzz::ByteSource in(data, size);
    if (in.u8() & 1)
        forward_key(in);
    else
        origin_check(in);
    return 0;
}
