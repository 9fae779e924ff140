#include "daemon/dive/dive_sampler.hpp"

#include <algorithm>
#include <climits>
#include <utility>
#include <vector>

namespace caracara {

namespace {
int16_t clamp16(int32_t v) { return static_cast<int16_t>(std::clamp<int32_t>(v, INT16_MIN + 1, INT16_MAX)); }
} // namespace

const dive::Sample& DiveSampler::sample(uint32_t t_100us) {
    dive::Sample& s = sample_;
    std::vector<uint16_t> room = std::move(s.distances); // its capacity, kept from the last sample
    s = {};
    s.distances = std::move(room);
    s.t_100us = t_100us;
    for (std::size_t i = 0; i < dive::kThrusters; ++i) {
        s.requested[i] = clamp16(vehicle_.readings().requested_values()[i]);
        s.applied[i] = clamp16(vehicle_.readings().order_value(i));
    }
    s.budget_limit = clamp16(vehicle_.readings().budget_limit());
    const BusTelemetry& bt = bus_.monitor().telemetry();
    s.flags = static_cast<uint8_t>((vehicle_.readings().saturated() ? dive::kSaturated : 0) |
                                   (vehicle_.readings().safety().kill_switch_set() ? dive::kKillSwitch : 0) |
                                   (teensy_.telemetry().online ? dive::kTeensyOnline : 0) |
                                   (vehicle_.readings().kill_output_asserted() ? dive::kKillOutput : 0) |
                                   (static_cast<unsigned>(bt.state) << dive::kBusStateShift));
    for (std::size_t i = 0; i < dive::kThrusters && i < bus_.size(); ++i) {
        const ThrusterDriver& d = bus_.thruster(i);
        dive::ThrusterSample& t = s.thrusters[i];
        t.flags = d.online() ? dive::kOnline : 0;
        if (const auto& st = d.last_status()) {
            t.flags |= dive::kStatusKnown;
            t.faults = st->faults.bits;
            if (st->current_deciamps) {
                t.flags |= dive::kCurrentKnown;
                t.current_da = *st->current_deciamps;
            }
            if (st->temperature_c)
                t.temperature_c = *st->temperature_c;
            if (st->speed_motor)
                t.speed = clamp16(*st->speed_motor);
        }
        const ThrusterCounters& c = d.counters();
        t.nacks = static_cast<uint32_t>(c.nacks);
        t.bad_replies = static_cast<uint32_t>(c.bad_replies);
        t.errors = static_cast<uint32_t>(c.order_failures + c.status_failures);
    }
    const TeensyTelemetry& tt = teensy_.telemetry();
    for (std::size_t k = 0; k < 3; ++k)
        s.orientation[k] = static_cast<float>(tt.orientation[k]);
    s.distances.assign(tt.distances.begin(), tt.distances.begin() + std::min(tt.distances.size(), dive::kMaxDistances));
    s.bus_errors = static_cast<uint32_t>(bt.errors);
    s.bus_recoveries = static_cast<uint32_t>(bt.recoveries);
    return s;
}

} // namespace caracara
