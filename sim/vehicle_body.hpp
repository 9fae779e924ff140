// A simple rigid-body model of the vehicle, pushed by the thrusters' actual speeds.
//
// Why so simple: the simulator has to show that thrust commands move the vehicle in the
// direction the seed's axis table promises (and that the Teensy's orientation answers follow),
// not to predict real hydrodynamics. Each of the six axes is an independent first-order
// system; pitch and roll also feel a restoring moment because the vehicle is bottom-heavy.
#pragma once

#include "core/vehicle_geometry.hpp"
#include "sim/stepped.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <optional>

namespace caracara::sim {

// Column order of the axis table and of generalised forces.
enum class BodyAxis : uint8_t { X = 0, Y = 1, Z = 2, Yaw = 3, Pitch = 4, Roll = 5 };

// Radians. yaw: clockwise viewed from above; pitch: nose up; roll: clockwise viewed from the back.
struct BodyAttitude {
    double yaw = 0.0;
    double pitch = 0.0;
    double roll = 0.0;
};

// World frame = the body frame at yaw 0: x towards port, y forward, depth positive downwards.
struct BodyPosition {
    double x = 0.0;
    double y = 0.0;
    double depth = 0.0;
};

using AxisTable = std::array<std::array<double, 6>, 8>;

struct VehicleBodyConfig {
    // Rows are motors 0..7, columns x, y, z, yaw, pitch, roll (seed "caracara-usb-packet").
    AxisTable axes = seed_axis_table();
    // Angular: rate' = k_torque * torque - k_damp * rate (- k_restore * sin(angle) for pitch/roll).
    // With torque normalised to [-1, 1], the steady yaw rate at full command is k_torque / k_damp.
    double k_torque = 2.0;  // rad/s^2 per unit torque
    double k_damp = 2.0;    // 1/s
    double k_restore = 4.0; // 1/s^2, bottom-heaviness
    // Translational: v' = k_force * force - k_drag * v; full command settles at k_force / k_drag.
    double k_force = 1.0; // m/s^2 per unit force
    double k_drag = 1.0;  // 1/s
    // Long steps are split so the explicit integration stays stable.
    double max_substep_s = 0.01;
    // The vehicle's description (caracarad.toml's [vehicle] and thruster placements, the one
    // caracara-ros maps a Wrench in newtons through): with its mass, translation takes each
    // thruster's thrust in newtons (the force curve) through the geometry, v' = F / m - k_drag * v;
    // with its inertia, rotation likewise, rate' = torque / I - k_damp * rate (- restoring).
    std::optional<VehicleGeometry> vehicle;

    static AxisTable seed_axis_table();
};

class VehicleBody : public Stepped {
public:
    // Returns each thruster's actual thrust as a fraction of full power (-1..+1).
    using ThrustSource = std::function<std::array<double, 8>()>;

    explicit VehicleBody(ThrustSource thrust, VehicleBodyConfig cfg = {});

    void step(double dt_s, uint64_t now_ns) override;

    // Generalised force per axis: the thrust vector projected onto each axis column, divided by
    // the column's absolute sum so that a full command on one axis gives exactly +-1.
    std::array<double, 6> generalised_force() const;
    // What the thrust does to each axis (BodyAxis order, the seed's senses): m/s^2 and rad/s^2
    // before drag, damping and restoring; in newtons through the description where it gives the
    // mass (translation) and the inertia (rotation), else k_force / k_torque times the above.
    std::array<double, 6> thrust_acceleration() const;

    BodyAttitude attitude() const { return att_; }
    double yaw() const { return att_.yaw; }
    double pitch() const { return att_.pitch; }
    double roll() const { return att_.roll; }
    // rad/s, same signs as the angles.
    BodyAttitude rates() const { return rate_; }
    BodyPosition position() const { return pos_; }
    // World-frame velocity, m/s.
    BodyPosition velocity() const { return vel_; }
    const VehicleBodyConfig& config() const { return cfg_; }

    // For tests and the inspection API: put the vehicle somewhere, at rest.
    void set_attitude(const BodyAttitude& a);
    void set_position(const BodyPosition& p);
    void reset();

    // Maps any angle to (-pi, pi].
    static double wrap_angle(double a);

private:
    void substep(double dt, const std::array<double, 6>& f);

    ThrustSource thrust_;
    VehicleBodyConfig cfg_;
    BodyAttitude att_{};
    BodyAttitude rate_{};
    BodyPosition pos_{};
    BodyPosition vel_{};
};

} // namespace caracara::sim
