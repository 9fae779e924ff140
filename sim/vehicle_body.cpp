#include "sim/vehicle_body.hpp"

#include "core/frames.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>

namespace caracara::sim {

AxisTable VehicleBodyConfig::seed_axis_table() {
    //        x     y     z    yaw  pitch  roll
    return {{
        {{-1.0, +1.0, 0.0, +1.0, 0.0, 0.0}},  // 0
        {{0.0, 0.0, +1.0, 0.0, -1.0, -1.0}},  // 1
        {{+1.0, +1.0, 0.0, +1.0, 0.0, 0.0}},  // 2
        {{0.0, 0.0, +1.0, 0.0, +1.0, -1.0}},  // 3
        {{-1.0, +1.0, 0.0, -1.0, 0.0, 0.0}},  // 4
        {{0.0, 0.0, +1.0, 0.0, +1.0, +1.0}},  // 5
        {{+1.0, +1.0, 0.0, -1.0, 0.0, 0.0}},  // 6
        {{0.0, 0.0, +1.0, 0.0, -1.0, +1.0}},  // 7
    }};
}

VehicleBody::VehicleBody(ThrustSource thrust, VehicleBodyConfig cfg) : thrust_(std::move(thrust)), cfg_(cfg) {
    if (!thrust_)
        throw std::invalid_argument("VehicleBody needs a thrust source");
    for (double k : {cfg_.k_torque, cfg_.k_damp, cfg_.k_restore, cfg_.k_force, cfg_.k_drag})
        if (!std::isfinite(k) || k < 0.0)
            throw std::invalid_argument("VehicleBody coefficients must be finite and non-negative");
    if (!std::isfinite(cfg_.max_substep_s) || cfg_.max_substep_s <= 0.0)
        throw std::invalid_argument("VehicleBody max_substep_s must be positive");
    for (const auto& row : cfg_.axes)
        for (double a : row)
            if (!std::isfinite(a))
                throw std::invalid_argument("VehicleBody axis table must be finite");
}

double VehicleBody::wrap_angle(double a) {
    if (!std::isfinite(a))
        return 0.0;
    double r = std::remainder(a, 2.0 * std::numbers::pi); // [-pi, pi]
    if (r <= -std::numbers::pi)
        r += 2.0 * std::numbers::pi;
    return r;
}

std::array<double, 6> VehicleBody::generalised_force() const {
    std::array<double, 8> t = thrust_();
    std::array<double, 6> f{};
    for (std::size_t j = 0; j < 6; ++j) {
        double sum = 0.0;
        double norm = 0.0;
        for (std::size_t i = 0; i < 8; ++i) {
            // A model that reports out-of-range or NaN thrust must not blow the body up.
            double ti = std::isfinite(t[i]) ? std::clamp(t[i], -1.0, 1.0) : 0.0;
            sum += ti * cfg_.axes[i][j];
            norm += std::abs(cfg_.axes[i][j]);
        }
        f[j] = norm > 0.0 ? sum / norm : 0.0;
    }
    return f;
}

std::array<double, 6> VehicleBody::thrust_acceleration() const {
    const std::array<double, 6> f = generalised_force();
    std::array<double, 6> a{};
    for (std::size_t j = 0; j < 6; ++j)
        a[j] = (j < 3 ? cfg_.k_force : cfg_.k_torque) * f[j];
    const std::optional<VehicleGeometry>& v = cfg_.vehicle;
    if (!v || (!v->mass_kg && !v->inertia_kg_m2))
        return a;
    std::array<double, 8> t = thrust_();
    for (double& ti : t)
        ti = std::isfinite(ti) ? std::clamp(ti, -1.0, 1.0) : 0.0;
    // The wrench in REP 103's FLU, turned into the seed's axes this body moves in (core/frames).
    const AxisDemand w = frames::from_flu(v->wrench_of(t));
    if (v->mass_kg)
        for (std::size_t j = 0; j < 3; ++j)
            a[j] = w[j] / *v->mass_kg;
    if (v->inertia_kg_m2) { // yaw is about z (up), pitch about y (left), roll about x (forward)
        a[3] = w[3] / v->inertia_kg_m2->z;
        a[4] = w[4] / v->inertia_kg_m2->y;
        a[5] = w[5] / v->inertia_kg_m2->x;
    }
    return a;
}

void VehicleBody::step(double dt_s, uint64_t now_ns) {
    (void)now_ns;
    if (!std::isfinite(dt_s) || dt_s <= 0.0)
        return;
    // Thrust is sampled once per step: the thruster models change on the same tick anyway.
    const std::array<double, 6> f = thrust_acceleration();
    double left = dt_s;
    while (left > 0.0) {
        double h = std::min(left, cfg_.max_substep_s);
        substep(h, f);
        left -= h;
    }
}

void VehicleBody::substep(double dt, const std::array<double, 6>& f) { // f: thrust_acceleration()
    // Semi-implicit Euler: update rates first, then angles with the new rates (stable for
    // the damped oscillator that pitch and roll are).
    rate_.yaw += dt * (f[3] - cfg_.k_damp * rate_.yaw);
    rate_.pitch += dt * (f[4] - cfg_.k_damp * rate_.pitch - cfg_.k_restore * std::sin(att_.pitch));
    rate_.roll += dt * (f[5] - cfg_.k_damp * rate_.roll - cfg_.k_restore * std::sin(att_.roll));
    att_.yaw = wrap_angle(att_.yaw + dt * rate_.yaw);
    att_.pitch = wrap_angle(att_.pitch + dt * rate_.pitch);
    att_.roll = wrap_angle(att_.roll + dt * rate_.roll);

    // Horizontal force acts along the body axes, so rotate it into the world frame by yaw
    // (clockwise from above): port = (cos, sin), forward = (-sin, cos). Pitch and roll are
    // small on a bottom-heavy vehicle and are ignored here.
    const double c = std::cos(att_.yaw);
    const double s = std::sin(att_.yaw);
    const double fx = f[0] * c - f[1] * s;
    const double fy = f[0] * s + f[1] * c;
    vel_.x += dt * (fx - cfg_.k_drag * vel_.x);
    vel_.y += dt * (fy - cfg_.k_drag * vel_.y);
    vel_.depth += dt * (f[2] - cfg_.k_drag * vel_.depth);
    pos_.x += dt * vel_.x;
    pos_.y += dt * vel_.y;
    pos_.depth += dt * vel_.depth;
    // Neutrally buoyant, but it cannot rise above the surface.
    if (pos_.depth < 0.0) {
        pos_.depth = 0.0;
        vel_.depth = std::max(vel_.depth, 0.0);
    }
}

void VehicleBody::set_attitude(const BodyAttitude& a) {
    att_ = {wrap_angle(a.yaw), wrap_angle(a.pitch), wrap_angle(a.roll)};
    rate_ = {};
}

void VehicleBody::set_position(const BodyPosition& p) {
    pos_ = {std::isfinite(p.x) ? p.x : 0.0, std::isfinite(p.y) ? p.y : 0.0,
            std::isfinite(p.depth) ? std::max(p.depth, 0.0) : 0.0};
    vel_ = {};
}

void VehicleBody::reset() {
    att_ = {};
    rate_ = {};
    pos_ = {};
    vel_ = {};
}

} // namespace caracara::sim
