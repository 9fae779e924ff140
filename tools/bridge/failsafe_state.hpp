// The state message's failsafe parts, from the root object's properties: the active failsafes,
// and the daemon's deadlines as time left. SurfacingUntil and PilotLostKillAt are
// CLOCK_MONOTONIC microseconds on the vehicle, which this bridge shares (it runs beside
// caracarad), so it alone can turn them into milliseconds left that a page on the pilot's
// laptop counts down from; the configured pilot-lost persistence is what a page that lost its
// link counts down from itself (docs/cockpit.md, the banner).
#pragma once

#include "tools/client/client.hpp"
#include "tools/foxglove/channels.hpp"

#include <cstdint>
#include <vector>

namespace caracara::bridge {

// The daemon's Failsafes, a(ssi).
std::vector<foxglove::ActiveFailsafe> failsafes(const client::Props& root);

// Sets `state`'s ascent_left_ms, pilot_lost_left_ms and pilot_lost_ms from the root object's
// properties, now (CLOCK_MONOTONIC); none runs while the state is killed or powered off.
void add_time_left(const client::Props& root, foxglove::VehicleState& state);

} // namespace caracara::bridge
