// The -H value, [USER@]HOST[:PORT] (an IPv6 address in brackets: user@[fd00::1]:22), checked
// before anything runs. systemd's sd_bus_open_system_remote() also reads HOST:CONTAINER, so
// "pilot@host:notaport" would silently go to port 22 of host: here a port is a port (1..65535)
// or the value is refused as a usage error.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace caracara::client {

struct SshTarget {
    std::string user;   // "" when not given
    std::string host;   // without brackets
    std::string port;   // "" when not given, else 1..65535 in digits
    // "user@host" (brackets kept off: ssh takes the address bare), for ssh's destination.
    std::string destination() const { return user.empty() ? host : user + "@" + host; }
};

std::optional<SshTarget> parse_ssh_target(std::string_view value);

} // namespace caracara::client
