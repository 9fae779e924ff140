// The names of org.caracara.Vehicle1 on the bus: one definition for the daemon and its clients.
#pragma once

namespace caracara::dbus {

inline constexpr const char* kBusName = "org.caracara.Vehicle1";
inline constexpr const char* kRootPath = "/org/caracara/Vehicle1";
inline constexpr const char* kTeensyPath = "/org/caracara/Vehicle1/teensy";
inline constexpr const char* kBusPath = "/org/caracara/Vehicle1/bus";
inline constexpr const char* kVehicleIface = "org.caracara.Vehicle1";
inline constexpr const char* kThrusterIface = "org.caracara.Vehicle1.Thruster";
inline constexpr const char* kTeensyIface = "org.caracara.Vehicle1.Teensy";
inline constexpr const char* kBusIface = "org.caracara.Vehicle1.Bus";
inline constexpr const char* kErrorPrefix = "org.caracara.Vehicle1.Error.";

} // namespace caracara::dbus
