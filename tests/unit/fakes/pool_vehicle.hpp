// The vehicle in the pool as its Teensy (a FakeTeensyIo) reports it to direction detection:
// still, but while a thruster's last order on the fake wire is not zero, turned by kTurnRad
// along the rotation its mixing row gives it, times its mounting (+1 as configured, -1 mounted
// reversed, 0 its motor lead off); `turning`: a vehicle that keeps turning at 1 rad/s, never
// still. It runs on the rig's loop, a timer of its own setting the Teensy's attitude from the wire.
#pragma once

#include "core/mixing.hpp"
#include "sim/vehicle_body.hpp"
#include "tests/unit/fakes/daemon_rig.hpp"
#include "tests/unit/fakes/fake_teensy_io.hpp"

#include <array>

namespace caracara::test {

class PoolVehicle {
public:
    static constexpr double kTurnRad = 0.1; // ten times the default detect_threshold_mrad

    // Made after the rig (whose Teensy's side is `teensy`), gone before it.
    PoolVehicle(DaemonRig& rig, FakeTeensyIo& teensy);
    ~PoolVehicle();
    PoolVehicle(const PoolVehicle&) = delete;
    PoolVehicle& operator=(const PoolVehicle&) = delete;

    std::array<int, kMotorCount> mounting{1, 1, 1, 1, 1, 1, 1, 1};
    bool turning = false;

private:
    static int on_timer(sd_event_source* s, uint64_t usec, void* self);
    sim::BodyAttitude attitude() const;

    DaemonRig& rig_;
    FakeTeensyIo& teensy_;
    sd_event_source* timer_ = nullptr;
};

} // namespace caracara::test
