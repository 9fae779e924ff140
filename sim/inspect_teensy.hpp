// /org/caracara/Simulator1/teensy, org.caracara.Simulator1.Teensy: the simulated Teensy, its
// SPI port and the body it drives. Userdata: the SimVehicle.
#pragma once

#include <systemd/sd-bus.h>

namespace caracara::sim {

const sd_bus_vtable* teensy_inspection();

} // namespace caracara::sim
