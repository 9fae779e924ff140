// caracaractl monitor: live PropertiesChanged of every org.caracara.Vehicle1 object.
#pragma once

#include "tools/client/client.hpp"

#include <string_view>

namespace caracara::ctl {

using namespace caracara::client; // the vehicle's D-Bus client (tools/client)

// Prints the current state, then one timestamped line per change until SIGINT/SIGTERM (returns
// 0) or caracarad leaves the bus (returns 1); throws Failure when it cannot start. Unless `all`,
// the fast counters (is_fast_counter) and values announced again unchanged are left out, and an
// announcement of nothing else prints nothing.
int run_monitor(Client& client, bool all);

// The monotonic counters the daemon republishes at the telemetry rate (Cycles, OrdersSent, ...).
bool is_fast_counter(std::string_view iface, std::string_view property);

} // namespace caracara::ctl
