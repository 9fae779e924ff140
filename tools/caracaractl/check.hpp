// caracaractl check: the daemon's preflight (Preflight() on org.caracara.Vehicle1) as a go/no-go
// table, each no-go with what to do under it.
#pragma once

#include "tools/client/client.hpp"

namespace caracara::ctl {

// Prints the table; 0 when every item is go, 1 (kExitRefused) when one is not.
int run_check(caracara::client::Client& client);

} // namespace caracara::ctl
