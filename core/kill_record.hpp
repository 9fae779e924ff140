// What the latched kill was: its source, its reason and when it came (KillSource::None and
// empty while not killed). The safety machine's, read through SafetyMachine::kill_record().
#pragma once

#include "core/safety_state.hpp"

#include <cstdint>
#include <string>

namespace caracara {

struct KillRecord {
    KillSource source = KillSource::None;
    std::string reason;
    uint64_t at = 0; // monotonic ns; kept after a clear, as before
};

} // namespace caracara
