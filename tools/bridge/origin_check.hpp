// Which web pages may use the bridge (issue 46): a browser lets any page open a WebSocket to
// any address, localhost included, and says which page asks only in the Origin header. So
// every WebSocket upgrade and every request for vehicle data is judged by its Origin, before
// a token or a D-Bus connection: none (Foxglove desktop, scripts: not a browser page), the
// bridge's own (the cockpit it serves: Origin http://<its Host header>), or one given with
// --allow-origin are taken; anything else, "null" (sandboxed and file: pages) included, is
// refused. The own origin counts only where DNS rebinding cannot forge it: a Host of localhost
// or an IP address, or any Host when clients must bring the token (TCP); a page from
// http://attacker.example:8765 whose name resolves to 127.0.0.1 sends a matching Host too.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace caracara::bridge {

class OriginCheck {
public:
    enum class Verdict {
        NoOrigin,    // not a browser page
        Own,         // the page the bridge serves
        Allowed,     // on the allow-list
        Foreign,     // refused: another site, or another port of localhost
        Rebindable,  // refused: the bridge's Host is a name DNS rebinding can forge, and no token
    };

    OriginCheck() = default;
    // allowed: origins as given (validate them with normalize first); token: clients must bring one.
    OriginCheck(const std::vector<std::string>& allowed, bool token);

    // "scheme://host[:port]" lowercased, without the scheme's default port (as browsers send
    // it); nullopt when it is not that (a path, "null", no host, a bad port).
    static std::optional<std::string> normalize(std::string_view origin);
    // origin: the request's Origin header, when it has one; host: its Host header.
    Verdict judge(std::optional<std::string_view> origin, std::string_view host) const;
    bool refused(Verdict v) const { return v == Verdict::Foreign || v == Verdict::Rebindable; }
    const std::vector<std::string>& allowed() const { return allowed_; }

private:
    std::vector<std::string> allowed_;
    bool token_ = false;
};

} // namespace caracara::bridge
