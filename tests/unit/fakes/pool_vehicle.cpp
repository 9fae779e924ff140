#include "tests/unit/fakes/pool_vehicle.hpp"

#include "core/clock.hpp"

#include <cmath>
#include <numbers>

namespace caracara::test {

sim::BodyAttitude PoolVehicle::attitude() const {
    sim::BodyAttitude a;
    if (turning)
        a.yaw = std::remainder(double(monotonic_ns()) / 1e9, 2.0 * std::numbers::pi);
    DaemonRig* r = rig_.load();
    if (!r)
        return a;
    std::array<int32_t, kMotorCount> last{};
    for (const WireEvent& e : r->wire().events())
        if (e.kind == WireEvent::Kind::Order && e.thruster < kMotorCount)
            last[e.thruster] = e.value;
    const MixMatrix& mix = r->config().mixing;
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
