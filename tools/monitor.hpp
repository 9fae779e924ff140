// caracaractl monitor: live PropertiesChanged of every org.caracara.Vehicle1 object.
#pragma once

#include "client.hpp"

namespace caracaractl {

// Prints the current state, then one timestamped line per change until SIGINT/SIGTERM (returns
// 0) or caracarad leaves the bus (returns 1); throws Failure when it cannot start.
int run_monitor(Client& client);

} // namespace caracaractl
