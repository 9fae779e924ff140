// /org/caracara/Simulator1, org.caracara.Simulator1: the I2C bus and its lines, the GPIO
// lines, the wire log and timing. Userdata: the Inspector.
#pragma once

#include <systemd/sd-bus.h>

namespace caracara::sim {

const sd_bus_vtable* simulator_inspection();

} // namespace caracara::sim
