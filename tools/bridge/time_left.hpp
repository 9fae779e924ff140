// The daemon's failsafe deadlines as the state message's time left: SurfacingUntil and
// PilotLostKillAt are CLOCK_MONOTONIC microseconds on the vehicle, which this bridge shares
// (it runs beside caracarad), so it alone can turn them into milliseconds left that a page on
// the pilot's laptop counts down from; and the configured pilot-lost persistence, which a page
// that lost its link counts down from itself (docs/cockpit.md, the banner).
#pragma once

#include "tools/client/client.hpp"
#include "tools/foxglove/channels.hpp"

#include <cstdint>

namespace caracara::bridge {

// Sets `state`'s ascent_left_ms, pilot_lost_left_ms and pilot_lost_ms from the root object's
// properties at `now_us` (CLOCK_MONOTONIC); none runs while the state is killed or powered off.
void add_time_left(const client::Props& root, uint64_t now_us, foxglove::VehicleState& state);

} // namespace caracara::bridge
