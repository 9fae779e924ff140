#include "core/vehicle_geometry.hpp"

#include "core/mixing.hpp"

#include <algorithm>
#include <cmath>

namespace caracara {

namespace {

using frames::Vec3;

constexpr double kRootHalf = 0.70710678118654752;

Vec3 cross(const Vec3& a, const Vec3& b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }

// Column i of the force/torque matrix: the wrench of thruster i's unit push.
std::array<double, 6> column(const ThrusterPlacement& t) {
    const Vec3 m = cross(t.position, t.direction);
    return {t.direction.x, t.direction.y, t.direction.z, m.x, m.y, m.z};
}

} // namespace

VehicleGeometry::VehicleGeometry()
    : VehicleGeometry({{{{0.25, 0.2, 0}, {kRootHalf, -kRootHalf, 0}},  // 0 front left: forward, starboard, clockwise
                        {{0.25, 0.2, 0}, {0, 0, -1}},                  // 1 front left: down
                        {{-0.25, 0.2, 0}, {kRootHalf, kRootHalf, 0}},  // 2 rear left: forward, port, clockwise
                        {{-0.25, 0.2, 0}, {0, 0, -1}},                 // 3 rear left
                        {{-0.25, -0.2, 0}, {kRootHalf, -kRootHalf, 0}}, // 4 rear right: forward, starboard, anti-
                        {{-0.25, -0.2, 0}, {0, 0, -1}},                // 5 rear right
                        {{0.25, -0.2, 0}, {kRootHalf, kRootHalf, 0}},  // 6 front right: forward, port, anti-
                        {{0.25, -0.2, 0}, {0, 0, -1}}}},               // 7 front right
                      ForceCurve()) {}

VehicleGeometry::VehicleGeometry(std::array<ThrusterPlacement, kMotorCount> placements, ForceCurve curve)
    : placements_(placements), curve_(std::move(curve)) {
    solve();
}

void VehicleGeometry::solve() {
    // Pseudo-inverse B+ = B^T (B B^T + eps I)^-1 of the 6 x 8 matrix B: the least thrust that gives
    // a wrench. The tiny eps keeps a geometry that cannot push along some axis solvable: that
    // axis's part of a wrench is then simply not pushed.
    std::array<std::array<double, 6>, kMotorCount> b{};
    for (std::size_t i = 0; i < kMotorCount; ++i)
        b[i] = column(placements_[i]);
    double a[6][12] = {};
    double scale = 0;
    for (std::size_t r = 0; r < 6; ++r)
        for (std::size_t c = 0; c < 6; ++c) {
            for (std::size_t i = 0; i < kMotorCount; ++i)
                a[r][c] += b[i][r] * b[i][c];
            scale = std::max(scale, a[r][c]);
        }
    for (std::size_t r = 0; r < 6; ++r) {
        a[r][r] += 1e-12 * std::max(scale, 1.0);
        a[r][6 + r] = 1;
    }
    // Gauss-Jordan with partial pivoting: B B^T + eps I is symmetric positive definite.
    for (std::size_t c = 0; c < 6; ++c) {
        std::size_t pivot = c;
        for (std::size_t r = c + 1; r < 6; ++r)
            if (std::fabs(a[r][c]) > std::fabs(a[pivot][c]))
                pivot = r;
        std::swap(a[c], a[pivot]);
        const double d = a[c][c];
        for (double& x : a[c])
            x /= d;
        for (std::size_t r = 0; r < 6; ++r)
            if (r != c) {
                const double f = a[r][c];
                for (std::size_t k = 0; k < 12; ++k)
                    a[r][k] -= f * a[c][k];
            }
    }
    for (std::size_t i = 0; i < kMotorCount; ++i)
        for (std::size_t c = 0; c < 6; ++c) {
            double s = 0;
            for (std::size_t r = 0; r < 6; ++r)
                s += b[i][r] * a[r][6 + c];
            pinv_[i][c] = s;
        }
}

WrenchMotors VehicleGeometry::motors_for(const frames::BodyMotion& w) const {
    const std::array<double, 6> v{w.linear.x, w.linear.y, w.linear.z, w.angular.x, w.angular.y, w.angular.z};
    static const char* const kNames[] = {"force.x", "force.y", "force.z", "torque.x", "torque.y", "torque.z"};
    WrenchMotors out;
    for (std::size_t k = 0; k < 6; ++k)
        if (!std::isfinite(v[k])) {
            out.error = std::string(kNames[k]) + ": must be a finite number of " + (k < 3 ? "newtons" : "newton-metres");
            return out;
        }
    // Each thruster's force as a fraction of its full thrust that way: the one saturation of
    // core/mixing keeps the wrench's direction when any exceeds full.
    std::array<double, kMotorCount> share{};
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        double f = 0;
        for (std::size_t k = 0; k < 6; ++k)
            f += pinv_[i][k] * v[k];
        share[i] = f / curve_.full_n(f < 0);
    }
    out.saturated = saturate_keeping_direction(share);
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        const double fraction = curve_.fraction(share[i] * curve_.full_n(share[i] < 0));
        out.motors[i] = static_cast<int32_t>(std::lround(std::clamp(fraction, -1.0, 1.0) * kMotorMax));
    }
    return out;
}

frames::BodyMotion VehicleGeometry::wrench_of(const std::array<double, kMotorCount>& fractions) const {
    frames::BodyMotion w;
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        const double f = curve_.force_n(fractions[i]);
        const std::array<double, 6> c = column(placements_[i]);
        w.linear = {w.linear.x + f * c[0], w.linear.y + f * c[1], w.linear.z + f * c[2]};
        w.angular = {w.angular.x + f * c[3], w.angular.y + f * c[4], w.angular.z + f * c[5]};
    }
    return w;
}

} // namespace caracara
