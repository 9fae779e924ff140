// DetectDirections() on org.caracara.Vehicle1: the daemon's direction detection run for a caller,
// answered when it ends: each thruster's (verdict, yaw, pitch, roll change, change along its
// row, margin) and the [[thruster]] fragment, or the error that ended it.
#pragma once

#include "daemon/commissioning/direction_detection.hpp"

#include <string>
#include <systemd/sd-bus.h>

namespace caracara::dbus {

// Starts the detection for `caller`; the reply is sent later. 1, as an sd-bus handler returns.
int run_detection(sd_bus_message* call, DirectionDetection& detection, const std::string& caller);

} // namespace caracara::dbus
