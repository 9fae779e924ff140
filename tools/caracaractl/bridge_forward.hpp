// caracaractl -H pilot@vehicle bridge: brings caracara-bridge's Unix socket on the vehicle to a
// local port with OpenSSH's socket forwarding (ssh -N -L 127.0.0.1:PORT:SOCKET), prints the
// address to open in Foxglove, and holds the forward until Ctrl-C (docs/foxglove.md).
#pragma once

#include "drivers/sdbus/sdbus.hpp"

#include <string>
#include <vector>

namespace caracara::ctl {

int run_bridge_forward(const caracara::dbus::BusChoice& choice, const std::vector<std::string>& args);
const char* bridge_forward_help();

} // namespace caracara::ctl
