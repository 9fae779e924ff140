#include "tests/unit/fakes/pool_vehicle.hpp"

#include "core/clock.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace caracara::test {

namespace {
// Half the fastest loop period the tests use (100 Hz): an order on the wire turns the vehicle
// before the next orientation frame asks.
constexpr uint64_t kUpdateUs = 5000;
} // namespace

PoolVehicle::PoolVehicle(DaemonRig& rig, FakeTeensyIo& teensy) : rig_(rig), teensy_(teensy) {
    // Accuracy 1 us: 0 would be sd-event's default, 250 ms.
    if (sd_event_add_time(rig_.event(), &timer_, CLOCK_MONOTONIC, 0, 1, on_timer, this) < 0)
        throw std::runtime_error("sd_event_add_time");
}

PoolVehicle::~PoolVehicle() {
    sd_event_source_disable_unref(timer_);
}

int PoolVehicle::on_timer(sd_event_source* s, uint64_t, void* self) {
    auto* v = static_cast<PoolVehicle*>(self);
    const sim::BodyAttitude a = v->attitude();
    v->teensy_.set_attitude(a);
    uint64_t now = 0;
    sd_event_now(sd_event_source_get_event(s), CLOCK_MONOTONIC, &now);
    sd_event_source_set_time(s, now + kUpdateUs);
    sd_event_source_set_enabled(s, SD_EVENT_ONESHOT);
    return 0;
}

sim::BodyAttitude PoolVehicle::attitude() const {
    sim::BodyAttitude a;
    if (turning)
        a.yaw = std::remainder(double(monotonic_ns()) / 1e9, 2.0 * std::numbers::pi);
    std::array<int32_t, kMotorCount> last{};
    for (const WireEvent& e : rig_.wire().events())
        if (e.kind == WireEvent::Kind::Order && e.thruster < kMotorCount)
            last[e.thruster] = e.value;
    const MixMatrix& mix = rig_.config().mixing;
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        if (last[i] == 0)
            continue;
        const double yaw = mix[i][std::size_t(Axis::Yaw)], pitch = mix[i][std::size_t(Axis::Pitch)],
                     roll = mix[i][std::size_t(Axis::Roll)];
        const double norm = std::sqrt(yaw * yaw + pitch * pitch + roll * roll);
        if (norm == 0.0)
            continue;
        const double k = (last[i] > 0 ? 1.0 : -1.0) * mounting[i] * kTurnRad / norm;
        a.yaw += k * yaw;
        a.pitch += k * pitch;
        a.roll += k * roll;
    }
    return a;
}

} // namespace caracara::test
