// caracaractl thrust/motion/packet: hold a motion command by re-sending it. caracarad zeroes the
// thrusters when no command arrives within CommandTimeoutMs and when the client that sent the
// last command leaves the bus, so a command only lasts as long as its sender keeps it alive.
#pragma once

#include "tools/client/client.hpp"

#include <cstdint>
#include <string>

namespace caracara::ctl {

using namespace caracara::client; // the vehicle's D-Bus client (tools/client)

// How long to hold: send once and leave (once), hold until SIGINT/SIGTERM (duration_usec 0),
// or hold for duration_usec.
struct HoldOptions {
    bool once = false;
    uint64_t duration_usec = 0;
};

// The interval between re-sends, for the daemon's CommandTimeoutMs: 100 ms, but at most a third
// of the timeout (0 = unknown: 100 ms).
uint64_t resend_interval_usec(uint32_t command_timeout_ms);

// Sends `member` on the vehicle object; its error throws Failure at once, as any call. Then, unless
// `once`, prints "holding <description> ...", re-sends the same command every
// resend_interval_usec() until a signal or the duration, prints "released: ..." and returns 0
// without sending a zero itself (the daemon zeroes when this client leaves). A re-send the daemon
// refuses, or a lost connection, throws Failure (exit 1 or 3) at once.
int hold_command(Client& client, const char* member, const Client::Appender& append,
                 const std::string& description, const HoldOptions& options);

// "3.0 s", "0.25 s", "90.0 s".
std::string format_seconds(uint64_t usec);

} // namespace caracara::ctl
