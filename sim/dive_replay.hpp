// caracara-sim --replay DIVE: the simulated thrusters and Teensy answer with a recorded dive's
// status and orientation instead of their models, so a dive's faults and readings play again
// against the daemon (docs/dive-format.md). Time zero is the moment caracarad releases the kill
// output (ClearKill: the start of a dive, as the recorder counts it). From there each physics
// step applies the samples due: every thruster's reported speed, current, temperature and
// fault bits; NACKs and corrupt replies where the recorded counters grew; the kill switch; the
// Teensy's orientation and distances. A recorded bus loss hangs the bus (SDA held for the SCL
// pulses the recorded recovery needed, SCL held low when it never came back). After the last
// sample its values stay.
#pragma once

#include "core/dive_format.hpp"
#include "sim/stepped.hpp"

#include <cstddef>
#include <cstdint>

namespace caracara::sim {

class SimVehicle;

class DiveReplay final : public Stepped {
public:
    DiveReplay(SimVehicle& vehicle, dive::Dive dive);
    void step(double dt_s, uint64_t now_ns) override;

    bool started() const { return started_; }
    bool finished() const { return finished_; }
    std::size_t samples_applied() const { return next_sample_; }

private:
    bool kill_output_released();
    void apply(const dive::Sample& s, const dive::Sample* before, uint64_t now_ns);
    void apply(const dive::Event& e, std::size_t index);
    void finish();

    SimVehicle& vehicle_;
    dive::Dive dive_;
    bool started_ = false;
    bool finished_ = false;
    uint64_t start_ns_ = 0;
    std::size_t next_sample_ = 0;
    std::size_t next_event_ = 0;
};

} // namespace caracara::sim
