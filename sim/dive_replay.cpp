#include "sim/dive_replay.hpp"

#include "sim/sim_vehicle.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace caracara::sim {

namespace {
// A motor value back to the SPEED byte the thruster reported (the IDS mapping).
uint8_t speed_byte(int16_t motor) {
    if (motor == dive::kUnknownSpeed)
        return 0x80;
    const long steps = std::lround(std::abs(motor) * 102.0 / 8850.0);
    if (steps == 0)
        return 0x80;
    return static_cast<uint8_t>(motor > 0 ? 0x80 + steps : 0x7F - steps);
}
} // namespace

DiveReplay::DiveReplay(SimVehicle& vehicle, dive::Dive dive) : vehicle_(vehicle), dive_(std::move(dive)) {}

bool DiveReplay::kill_output_released() {
    auto& gpio = vehicle_.gpio();
    const int line = gpio.find(GpioModel::kChip, "", static_cast<int>(GpioModel::kKillOut));
    return line >= 0 && gpio.requested(line) && gpio.get(line) == 0;
}

void DiveReplay::step(double, uint64_t now_ns) {
    if (finished_)
        return;
    if (!started_) {
        if (!kill_output_released())
            return;
        started_ = true;
        start_ns_ = now_ns;
        std::printf("caracara-sim: replay started (%zu samples, %zu events)\n", dive_.samples.size(),
                    dive_.events.size());
        std::fflush(stdout);
    }
    const uint64_t t = (now_ns - start_ns_) / 100'000;
    while (next_sample_ < dive_.samples.size() && dive_.samples[next_sample_].t_100us <= t) {
        apply(dive_.samples[next_sample_], next_sample_ ? &dive_.samples[next_sample_ - 1] : nullptr, now_ns);
        ++next_sample_;
    }
    while (next_event_ < dive_.events.size() && dive_.events[next_event_].t_100us <= t) {
        apply(dive_.events[next_event_], next_event_);
        ++next_event_;
    }
    if (next_sample_ == dive_.samples.size() && next_event_ == dive_.events.size())
        finish();
}

void DiveReplay::apply(const dive::Sample& s, const dive::Sample* before, uint64_t now_ns) {
    auto& thrusters = vehicle_.thrusters();
    for (std::size_t i = 0; i < thrusters.size() && i < dive::kThrusters; ++i) {
        const dive::ThrusterSample& r = s.thrusters[i];
        ThrusterModel& m = *thrusters[i];
        if (r.flags & dive::kStatusKnown)
            m.replay(ThrusterModel::Replayed{speed_byte(r.speed), r.current_da, r.temperature_c, r.faults});
        if (!before)
            continue;
        const dive::ThrusterSample& b = before->thrusters[i];
        m.set_nack(r.nacks > b.nacks);
        if (r.bad_replies > b.bad_replies)
            m.corrupt_replies(r.bad_replies - b.bad_replies, ThrusterModel::Corrupt::Checksum);
    }
    vehicle_.teensy().replay_orientation(BodyAttitude{s.orientation[0], s.orientation[1], s.orientation[2]});
    for (std::size_t k = 0; k < s.distances.size(); ++k)
        vehicle_.teensy().set_distance_mm(k, s.distances[k]);
    const bool switch_set = s.flags & dive::kKillSwitch;
    if (switch_set != vehicle_.gpio().kill_switch_engaged())
        vehicle_.gpio().set_kill_switch(switch_set, now_ns);
}

void DiveReplay::apply(const dive::Event& e, std::size_t index) {
    if (e.kind != dive::EventKind::BusLost)
        return;
    // How many pulses the recorded bus clear needed, from the recovery that followed.
    for (std::size_t k = index + 1; k < dive_.events.size(); ++k)
        if (dive_.events[k].kind == dive::EventKind::BusRestored) {
            vehicle_.i2c().hang_sda(dive_.events[k].value ? dive_.events[k].value : 1);
            return;
        }
    vehicle_.i2c().hang_scl();
}

void DiveReplay::finish() {
    // The last sample stays: what the daemon sees after the dive does not depend on how long
    // after it someone looks (the regression logs compare it).
    finished_ = true;
    for (auto& m : vehicle_.thrusters())
        m->set_nack(false);
    std::printf("caracara-sim: replay finished; the last sample stays\n");
    std::fflush(stdout);
}

} // namespace caracara::sim
