// The dive recorder (docs/dive-format.md): a VehicleObserver that opens a dive when the
// vehicle arms, takes a sample of the whole vehicle every control-loop cycle and an event for
// every state change (with its kill source, reason and calling client), fault change, bus loss
// and recovery, profile switch, motor test and direction detection step (its
// CommissioningEvents'), and closes the dive at the next kill or power-off. Samples (its
// DiveSampler's) are encoded into memory on the loop (a few hundred bytes, no system call) and
// handed to the DiveWriter's thread once a second, so a crash loses at most the last second,
// and at 64 KiB (a loop running flat out fills megabytes a second).
#pragma once

#include "core/config.hpp"
#include "core/dive_format.hpp"
#include "daemon/bus/thruster_bus.hpp"
#include "daemon/dive/commissioning_events.hpp"
#include "daemon/dive/dive_sampler.hpp"
#include "daemon/dive/dive_writer.hpp"
#include "daemon/teensy/teensy_port.hpp"
#include "daemon/vehicle/vehicle.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "daemon/interfaces/vehicle_observer.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace caracara {

class DiveRecorder final : public VehicleObserver {
public:
    DiveRecorder(const DaemonConfig& config, const Vehicle& vehicle, const ThrusterBus& bus, const TeensyPort& teensy,
                 const VehicleEvents& events, DiveWriter& writer, const MotorTest& motor_test,
                 const DirectionDetection& detection);

    // Opens a dive at once if the vehicle is already arming (control.arm_at_start).
    void start();
    // The daemon is stopping: the dive in progress ends ("stopped") and goes to the writer.
    void stop();
    bool recording() const { return recording_; }

    void vehicle_changed(uint32_t changes) override;
    void bus_lost(const std::string& reason) override;
    void bus_restored(uint32_t pulses, double milliseconds) override;
    void cycle(uint64_t now_ns) override;
    void failsafe(const ActiveFailsafe& f, bool raised) override;
    void motor_test(int32_t thruster, int32_t value) override;

private:
    void begin(uint64_t now_ns, const char* reason);
    void finish(uint64_t now_ns, const std::string& reason);
    void flush();
    uint32_t since_start(uint64_t now_ns) const;
    void add_event(dive::Event e, uint64_t now_ns);

    const DaemonConfig& config_;
    const Vehicle& vehicle_;
    const ThrusterBus& bus_;
    const VehicleEvents& events_;
    DiveWriter& writer_;
    DiveSampler sampler_;
    CommissioningEvents commissioning_;

    bool recording_ = false;
    bool started_ = false;
    uint64_t start_ns_ = 0;
    uint64_t last_flush_ns_ = 0;
    std::vector<uint8_t> records_;
    std::array<uint8_t, dive::kThrusters> faults_{};
};

} // namespace caracara
