#include "tools/bridge/failsafe_state.hpp"

#include "core/clock.hpp"

namespace caracara::bridge {

namespace {

uint64_t unsigned_of(const client::Props& p, const char* name) { return client::property(p, name).unsigned_integer(); }

// Milliseconds from `now_us` to `until_us`, rounded up so that a running countdown never reads
// 0 before its end; 0 once due, -1 when `until_us` is 0 (none runs).
int64_t left_ms(uint64_t until_us, uint64_t now_us) {
    if (until_us == 0)
        return -1;
    return until_us > now_us ? static_cast<int64_t>((until_us - now_us + 999) / 1000) : 0;
}

} // namespace

std::vector<foxglove::ActiveFailsafe> failsafes(const client::Props& root) {
    std::vector<foxglove::ActiveFailsafe> out;
    for (const client::Value& f : client::property(root, "Failsafes").items)
        if (f.items.size() == 3)
            out.push_back({f.items[0].s, f.items[1].s, f.items[2].integer()});
    return out;
}

void add_time_left(const client::Props& root, foxglove::VehicleState& state) {
    const uint64_t now_us = monotonic_ns() / 1000;
    // A kill ends both (the daemon clears the ascent's deadline at its next failsafe reading).
    const bool down = state.state == "killed" || state.state == "powered-off";
    state.ascent_left_ms = down ? -1 : left_ms(unsigned_of(root, "SurfacingUntil"), now_us);
    state.pilot_lost_left_ms = down ? -1 : left_ms(unsigned_of(root, "PilotLostKillAt"), now_us);
    state.pilot_lost_ms = root.contains("PilotLostPersistenceMs")
                              ? static_cast<int64_t>(unsigned_of(root, "PilotLostPersistenceMs"))
                              : -1;
}

} // namespace caracara::bridge
