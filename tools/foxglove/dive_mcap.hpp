// A recorded dive as MCAP, on the live bridge's channels (tools/foxglove/channels.hpp): each
// sample gives one message on every channel but /events, each dive event one foxglove.Log on
// /events (and the dive's end as a last one), all at the sample's or event's wall-clock time.
#pragma once

#include "core/dive_format.hpp"

#include <cstdint>
#include <vector>

namespace caracara::foxglove {

std::vector<uint8_t> dive_to_mcap(const caracara::dive::Dive& dive);

} // namespace caracara::foxglove
