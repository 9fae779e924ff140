// The [failsafe] table of caracarad.toml (daemon/caracarad.toml.example documents it):
//
//   [failsafe.water-detect]   action = "surface", persistence_ms = 2000
//   [failsafe.bus-lost]       action = "kill"    (fixed: anything weaker is refused)
//   [failsafe.surface]        heave = -0.5, duration_ms = 15000
#pragma once

#include "core/failsafe.hpp"
#include "core/toml_checker.hpp"

namespace caracara {

// The name of the error a weaker action for a fixed condition gets, in its message.
inline constexpr std::string_view kFixedFailsafeError = "FixedFailsafe";

void parse_failsafe(Checker& c, const toml::table& t, FailsafeSettings& out);

} // namespace caracara
