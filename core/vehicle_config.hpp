// The vehicle's description in caracarad.toml: [vehicle] (force curve, mass, inertia) and the
// [[thruster]] tables' position and direction, read into a VehicleGeometry by caracara-ros (a
// Wrench in newtons), caracara-sim (thrust in newtons) and caracarad's checker alike.
#pragma once

#include "core/vehicle_geometry.hpp"

#include <string>
#include <toml++/toml.h>

namespace caracara {

// Three finite numbers, each within `limit`, into `out` (a position, a direction; caracara-ros's
// sensor mounts too); false otherwise.
bool read_triple(const toml::node* n, double limit, frames::Vec3& out);

// Reads a parsed caracarad.toml into `out` (the defaults where a key is absent); "" or
// "<key>: <problem>", `out` unchanged then.
std::string parse_vehicle(const toml::table& root, VehicleGeometry& out);
// The file at `path`: "" or "<path>: <key>: <problem>".
std::string load_vehicle(const std::string& path, VehicleGeometry& out);

} // namespace caracara
