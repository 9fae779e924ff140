// caracaractl bridge's key (tools/caracaractl/forward_key.hpp): which request heads go on to
// the vehicle, the redirect that trades the query's key for the cookie, and the refusals.
#include "tests/catch.hpp"
#include "tools/caracaractl/forward_key.hpp"

using caracara::ctl::ForwardKey;
using V = ForwardKey::Verdict;

namespace {

const ForwardKey key("0123456789abcdef", 8765);

std::string head(const std::string& target, const std::string& headers = "") {
    return "GET " + target + " HTTP/1.1\r\nHost: localhost:8765\r\n" + headers + "\r\n";
}
const std::string kUpgrade = "Upgrade: websocket\r\nConnection: Upgrade\r\n";

} // namespace

TEST_CASE("a page load with the key in its query is redirected without it, setting the cookie", "[bridge]") {
    auto j = key.judge(head("/?key=0123456789abcdef"));
    CHECK(j.verdict == V::Redirect);
    CHECK(j.location == "/");
    j = key.judge(head("/index.html?a=1&key=0123456789abcdef&b=2"));
    CHECK(j.verdict == V::Redirect);
    CHECK(j.location == "/index.html?a=1&b=2");
    const std::string a = key.answer(j);
    CHECK(a.starts_with("HTTP/1.1 303 See Other\r\n"));
    CHECK(a.find("\r\nLocation: /index.html?a=1&b=2\r\n") != std::string::npos);
    CHECK(a.find("\r\nSet-Cookie: caracara_key_8765=0123456789abcdef; Path=/; HttpOnly; SameSite=Strict\r\n") !=
          std::string::npos);
    // The key written again in another item (bare, or as another name's value) goes too: the
    // Location stays in the browser's history.
    j = key.judge(head("/?1&&key=0123456789abcdef&0123456789abcdef&x=0123456789abcdef&b=2"));
    CHECK(j.verdict == V::Redirect);
    CHECK(j.location == "/?1&b=2");
}

TEST_CASE("a WebSocket upgrade with the key in its query, or any request with the cookie, is relayed", "[bridge]") {
    CHECK(key.judge(head("/?key=0123456789abcdef", kUpgrade)).verdict == V::Relay);
    CHECK(key.judge(head("/?key=0123456789abcdef", "upgrade: WebSocket\r\n")).verdict == V::Relay);
    CHECK(key.judge(head("/", "Cookie: caracara_key_8765=0123456789abcdef\r\n")).verdict == V::Relay);
    CHECK(key.judge(head("/dives/", "cookie: a=1; caracara_key_8765=0123456789abcdef; b=2\r\n")).verdict == V::Relay);
    CHECK(key.judge(head("/", kUpgrade + "Cookie: caracara_key_8765=0123456789abcdef\r\n")).verdict == V::Relay);
}

TEST_CASE("no key, a wrong key, another port's cookie or no HTTP: refused, saying why", "[bridge]") {
    auto j = key.judge(head("/", kUpgrade + "Origin: http://localhost:9000\r\n"));
    CHECK(j.verdict == V::NoKey);
    CHECK(j.origin == "http://localhost:9000");
    CHECK(key.answer(j).starts_with("HTTP/1.1 403 Forbidden\r\n"));
    CHECK(key.answer(j).find("needs the key of its session") != std::string::npos);
    CHECK(key.judge(head("/?key=0123456789abcdeX", kUpgrade)).verdict == V::WrongKey);
    CHECK(key.judge(head("/?key=0123456789abcdef0")).verdict == V::WrongKey);
    CHECK(key.judge(head("/?key=")).verdict == V::WrongKey);
    CHECK(key.judge(head("/?nokey=0123456789abcdef")).verdict == V::NoKey);
    CHECK(key.judge(head("/", "Cookie: caracara_key_8766=0123456789abcdef\r\n")).verdict == V::NoKey);
    CHECK(key.judge(head("/", "Cookie: caracara_key_8765=fedcba9876543210\r\n")).verdict == V::WrongKey);
    // The query wins over a stale cookie of an earlier session (a new key, the same port).
    CHECK(key.judge(head("/?key=0123456789abcdef", "Cookie: caracara_key_8765=old\r\n")).verdict == V::Redirect);
    CHECK(key.answer(key.judge(head("/?key=bad"))).find("wrong key") != std::string::npos);
    CHECK(key.judge("hello\r\n\r\n").verdict == V::BadRequest);
    CHECK(key.judge("GET http://localhost:8765/?key=0123456789abcdef HTTP/1.1\r\n\r\n").verdict == V::BadRequest);
    // A line break in the request line would come back in the redirect's Location as a header of
    // the client's (fuzz_bridge_http); a control byte in the Origin is logged as '?'.
    CHECK(key.judge("GET /?key=0123456789abcdef\nSet-Cookie: x=1 HTTP/1.1\r\n\r\n").verdict == V::BadRequest);
    // A space inside the target: the key, found past it, would stay in the Location (fuzz_bridge_http).
    CHECK(key.judge("GET /? key=0123456789abcdef HTTP/1.1\r\n\r\n").verdict == V::BadRequest);
    CHECK(key.judge("GET / HTTP/1.1\r\nOrigin: http://a\rforged\r\n\r\n").origin == "http://a?forged");
    CHECK(key.answer(key.judge("\r\n\r\n")).starts_with("HTTP/1.1 400 Bad Request\r\n"));
}

TEST_CASE("each session's key is fresh: 64 hex digits", "[bridge]") {
    const ForwardKey a = ForwardKey::random(8765), b = ForwardKey::random(8765);
    CHECK(a.key().size() == 64);
    CHECK(a.key().find_first_not_of("0123456789abcdef") == std::string::npos);
    CHECK(a.key() != b.key());
    CHECK(a.cookie_name() == "caracara_key_8765");
}
