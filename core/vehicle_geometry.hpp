// The vehicle as its thrusters push it: where each of the eight sits and which way a positive
// motor value pushes (REP 103's body FLU: x forward, y left, z up, metres, about the centre of
// mass), the thrusters' force curve, and, where given, the mass and the inertia. One description
// read from caracarad.toml ([vehicle] and the [[thruster]] tables' position and direction) by
// caracara-ros (a Wrench in newtons to motor values) and caracara-sim (thrust to acceleration).
#pragma once

#include "core/force_curve.hpp"
#include "core/frames.hpp"
#include "core/motor.hpp"

#include <array>
#include <optional>
#include <string>

namespace caracara {

struct ThrusterPlacement {
    frames::Vec3 position;   // metres, body FLU
    frames::Vec3 direction;  // unit vector: the push of a positive motor value
};

// A Wrench turned into motor values; `error` names the bad field (motors all zero then).
struct WrenchMotors {
    MotorValues motors{};
    bool saturated = false;  // some thruster would have exceeded full: all scaled by one factor
    std::string error;
    bool ok() const { return error.empty(); }
};

class VehicleGeometry {
public:
    // The seed's axis table as a vehicle ("caracara-usb-packet", axis table; core/mixing.hpp):
    // motors 0, 2, 4, 6 horizontal at 45 degrees in the corners, 1, 3, 5, 7 pushing down in the
    // corners, BTD150 curves, no mass given.
    VehicleGeometry();
    VehicleGeometry(std::array<ThrusterPlacement, kMotorCount> placements, ForceCurve curve);

    // The eight motor values that push `wrench` (newtons and newton-metres, body FLU): each
    // thruster's force by the pseudo-inverse of the geometry's force/torque matrix, scaled by one
    // factor when any exceeds its full thrust (the direction kept), through the force curve.
    WrenchMotors motors_for(const frames::BodyMotion& wrench) const;
    // The wrench (newtons, newton-metres, body FLU) that thrusters at these fractions of full
    // demand (-1..1, motor order) push.
    frames::BodyMotion wrench_of(const std::array<double, kMotorCount>& fractions) const;

    const std::array<ThrusterPlacement, kMotorCount>& placements() const { return placements_; }
    const ForceCurve& curve() const { return curve_; }
    std::optional<double> mass_kg;
    std::optional<frames::Vec3> inertia_kg_m2;  // about x, y, z of body FLU (principal axes)

private:
    void solve(); // the pseudo-inverse from the placements

    std::array<ThrusterPlacement, kMotorCount> placements_;
    ForceCurve curve_;
    std::array<std::array<double, 6>, kMotorCount> pinv_{}; // [motor][fx fy fz tx ty tz]
};

} // namespace caracara
