// caracaractl -H pilot@vehicle bridge: brings caracara-bridge's Unix socket on the vehicle to a
// private local socket with OpenSSH's socket forwarding (ssh -N -L DIR/bridge.sock:SOCKET),
// serves it on 127.0.0.1:PORT to requests that bring this session's key (ForwardRelay), prints
// the addresses to open in Foxglove and a browser, with the key, and holds the forward until
// Ctrl-C (docs/foxglove.md).
#pragma once

#include "drivers/sdbus/sdbus.hpp"

#include <string>
#include <vector>

namespace caracara::ctl {

int run_bridge_forward(const caracara::dbus::BusChoice& choice, const std::vector<std::string>& args);
const char* bridge_forward_help();

} // namespace caracara::ctl
