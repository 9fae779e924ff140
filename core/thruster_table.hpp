// The vehicle's thrusters in caracarad.toml (daemon/caracarad.toml.example documents them): the
// eight [[thruster]] tables, each thruster's address, mux segment and variant, checked as a set
// (no two answering at the same address on one segment), and the [mixing] table's matrix.
#pragma once

#include "core/mixing.hpp"
#include "core/motor.hpp"
#include "core/thruster_config.hpp"
#include "core/toml_checker.hpp"

#include <array>

namespace caracara {

// Leaves `out` as it is (the default vehicle) when there is no [[thruster]] table or one is wrong.
void parse_thrusters(Checker& c, const toml::table& root, std::array<ThrusterConfig, kMotorCount>& out);
void parse_mixing(Checker& c, const toml::table& t, MixMatrix& out);

} // namespace caracara
