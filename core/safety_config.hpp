// The safety state machine's (core/safety) times and start, from [control] (safety_config in
// core/config).
#pragma once

#include <cstdint>

namespace caracara {

constexpr uint64_t ms_to_ns(uint64_t ms) { return ms * 1'000'000; }

struct SafetyConfig {
    uint64_t arming_delay_ns = ms_to_ns(3000);     // as the board firmware did
    uint64_t command_timeout_ns = ms_to_ns(500);
    // Come up killed (source Start): a restart after a crash, an upgrade or a reboot must not
    // drive again by itself. The daemon sets it unless control.arm_at_start is true.
    bool start_killed = false;
};

} // namespace caracara
