// The vehicle in the pool as its Teensy (a FakeTeensy) reports it to direction detection: still,
// but while a thruster's last order on the fake wire is not zero, turned by kTurnRad along the
// rotation its mixing row gives it, times its mounting (+1 as configured, -1 mounted reversed, 0
// its motor lead off). `turning`: a vehicle that keeps turning at 1 rad/s, never still.
// attitude() is asked on the Teensy worker's thread: the rig is attached once it exists.
#pragma once

#include "core/mixing.hpp"
#include "sim/vehicle_body.hpp"
#include "tests/unit/fakes/daemon_rig.hpp"

#include <array>
#include <atomic>

namespace caracara::test {

class PoolVehicle {
public:
    static constexpr double kTurnRad = 0.1; // ten times the default detect_threshold_mrad

    void attach(DaemonRig& rig) { rig_ = &rig; }
    sim::BodyAttitude attitude() const;

    std::array<int, kMotorCount> mounting{1, 1, 1, 1, 1, 1, 1, 1};
    std::atomic<bool> turning{false};

private:
    std::atomic<DaemonRig*> rig_{nullptr};
};

} // namespace caracara::test
