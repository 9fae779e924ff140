// caracaractl scan: the daemon's bus scan (ScanBus, docs/commissioning.md), printed as a table of
// what answered and a verdict per configured thruster, each mismatch with what to do.
#pragma once

#include "tools/client/client.hpp"

namespace caracara::ctl {

// Exit 0 only when the bus matches the configuration (every thruster ok, nothing unexpected),
// 1 when it does not or the daemon refused. Throws Failure.
int scan_bus(caracara::client::Client& client);

} // namespace caracara::ctl
