// caracara-bridge's Origin check (tools/bridge/origin_check.hpp): the pages that may upgrade a
// WebSocket or read the dives, and the allow-list's entries as a browser would send them.
#include "tests/catch.hpp"
#include "tools/bridge/origin_check.hpp"

using caracara::bridge::OriginCheck;
using V = OriginCheck::Verdict;

TEST_CASE("an allow-list entry is an origin as browsers send it, or refused", "[bridge]") {
    CHECK(OriginCheck::normalize("https://app.foxglove.dev") == "https://app.foxglove.dev");
    CHECK(OriginCheck::normalize("HTTPS://App.Foxglove.DEV") == "https://app.foxglove.dev");
    CHECK(OriginCheck::normalize("https://app.foxglove.dev:443") == "https://app.foxglove.dev");
    CHECK(OriginCheck::normalize("http://localhost:80") == "http://localhost");
    CHECK(OriginCheck::normalize("http://localhost:08080") == "http://localhost:8080");
    CHECK(OriginCheck::normalize("http://[::1]:9000") == "http://[::1]:9000");
    for (const char* bad : {"app.foxglove.dev", "https://app.foxglove.dev/", "https://app.foxglove.dev/x", "null", "",
                            "https://", "https://a b", "http://localhost:0", "http://localhost:65536", "http://host:x",
                            "http://user@host", "://host", "1http://host"})
        CHECK_FALSE(OriginCheck::normalize(bad));
}

TEST_CASE("no Origin, the bridge's own page and the allow-list are taken; any other page refused", "[bridge]") {
    const OriginCheck unix_socket({"https://app.foxglove.dev", "http://localhost:9001"}, false);
    CHECK(unix_socket.judge(std::nullopt, "localhost:8765") == V::NoOrigin);
    CHECK(unix_socket.judge(std::nullopt, "") == V::NoOrigin);
    CHECK(unix_socket.judge("http://localhost:8765", "localhost:8765") == V::Own);
    CHECK(unix_socket.judge("http://127.0.0.1:8765", "127.0.0.1:8765") == V::Own);
    CHECK(unix_socket.judge("http://[::1]:8765", "[::1]:8765") == V::Own);
    CHECK(unix_socket.judge("https://app.foxglove.dev", "localhost:8765") == V::Allowed);
    CHECK(unix_socket.judge("http://localhost:9001", "localhost:8765") == V::Allowed);
    // Another port of localhost is another origin (though the same site for cookies).
    CHECK(unix_socket.judge("http://localhost:9000", "localhost:8765") == V::Foreign);
    CHECK(unix_socket.judge("http://127.0.0.1:8765", "localhost:8765") == V::Foreign);
    CHECK(unix_socket.judge("https://localhost:8765", "localhost:8765") == V::Foreign);
    CHECK(unix_socket.judge("https://evil.example", "localhost:8765") == V::Foreign);
    CHECK(unix_socket.judge("null", "localhost:8765") == V::Foreign);
    CHECK(unix_socket.judge("", "localhost:8765") == V::Foreign);
    CHECK(unix_socket.judge("http://localhost:8765", "") == V::Foreign);
    // DNS rebinding: a name that resolves to 127.0.0.1 brings a Host that matches its Origin.
    CHECK(unix_socket.judge("http://evil.example:8765", "evil.example:8765") == V::Rebindable);
    CHECK(unix_socket.refused(V::Rebindable));
    CHECK(unix_socket.refused(V::Foreign));
    CHECK_FALSE(unix_socket.refused(V::Own));
    // With the token (TCP), the rebinding page has no token: the vehicle's name is its own.
    const OriginCheck tcp({}, true);
    CHECK(tcp.judge("http://rov.local:8765", "rov.local:8765") == V::Own);
    CHECK(tcp.judge("http://evil.example", "rov.local:8765") == V::Foreign);
    CHECK(tcp.judge("https://app.foxglove.dev", "rov.local:8765") == V::Foreign);
}
