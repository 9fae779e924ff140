// The key of one `caracaractl bridge` session (issue 46): the forwarded port is a TCP port on
// the topside's loopback, which any local user (and any page in any browser) can reach, so
// each request's head must bring the key before a byte goes to the vehicle. A browser brings
// it once in the printed address's query (?key=) and is answered a redirect to the same
// address without it, with the key in an HttpOnly cookie named after the port (cookies do not
// tell localhost's ports apart, so two forwards each keep their own); a WebSocket URL may keep
// the query (Foxglove: ws://localhost:PORT/?key=...). Pure: ForwardRelay does the I/O.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace caracara::ctl {

class ForwardKey {
public:
    enum class Verdict {
        Relay,    // the key (query on an upgrade, or cookie): relay the request as it is
        Redirect, // the key in the query of a page load: 303 to `location`, setting the cookie
        NoKey,    // refused: neither query nor cookie
        WrongKey, // refused: a key, not this session's
        BadRequest, // refused: not an HTTP request head
    };
    struct Judgement {
        Verdict verdict;
        std::string location; // Redirect: the target without the key
        std::string origin;    // the request's Origin header, for the log ("" when none)
    };

    // A fresh random key (getrandom, 32 bytes as hex) for the forward on `port`.
    static ForwardKey random(uint16_t port);
    ForwardKey(std::string key, uint16_t port) : key_(std::move(key)), port_(port) {}

    const std::string& key() const { return key_; }
    std::string cookie_name() const { return "caracara_key_" + std::to_string(port_); }
    // head: a request's bytes up to and including its blank line.
    Judgement judge(std::string_view head) const;
    // The complete HTTP answer for a verdict other than Relay.
    std::string answer(const Judgement& j) const;

private:
    std::string key_;
    uint16_t port_;
};

} // namespace caracara::ctl
