// Preflight() on org.caracara.Vehicle1: the daemon's preflight run for a caller, who is answered
// when its window is over with a(sbss): each item's name, go, what was observed, what to do.
#pragma once

#include "daemon/commissioning/preflight.hpp"

#include <systemd/sd-bus.h>

namespace caracara::dbus {

// Starts (or joins) the preflight; the reply is sent later. 1, as an sd-bus handler returns.
int run_preflight(sd_bus_message* call, Preflight& preflight);

} // namespace caracara::dbus
