#include "core/vehicle_geometry.hpp"

#include "core/mixing.hpp"
#include "core/toml_text.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace caracara {

namespace {

using frames::Vec3;

Vec3 cross(const Vec3& a, const Vec3& b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }

// Column i of the force/torque matrix: the wrench of thruster i's unit push.
std::array<double, 6> column(const ThrusterPlacement& t) {
    const Vec3 m = cross(t.position, t.direction);
    return {t.direction.x, t.direction.y, t.direction.z, m.x, m.y, m.z};
}

constexpr double kMaxOffsetM = 10.0; // as a sensor's mount: a typo (mm for m) is refused
constexpr double kRootHalf = 0.70710678118654752;

// Three finite numbers within `limit`; false otherwise.
bool triple(const toml::node* n, double limit, Vec3& out) {
    const toml::array* a = n ? n->as_array() : nullptr;
    if (!a || a->size() != 3)
        return false;
    double v[3];
    for (std::size_t i = 0; i < 3; ++i) {
        const auto d = (*a)[i].value<double>();
        if (!d || !std::isfinite(*d) || std::fabs(*d) > limit)
            return false;
        v[i] = *d;
    }
    out = {v[0], v[1], v[2]};
    return true;
}

std::string read_curve(const toml::table& v, const char* key, std::vector<double>& out) {
    const toml::node* n = v.get(key);
    if (!n)
        return "";
    const toml::array* a = n->as_array();
    out.clear();
    for (std::size_t i = 0; a && i < a->size(); ++i) {
        const auto d = (*a)[i].value<double>();
        out.push_back(d ? *d : NAN);
    }
    if (std::string e = a ? ForceCurve::check(out) : "must be an array of thrusts in newtons"; !e.empty())
        return std::string("vehicle.") + key + ": " + e;
    return "";
}

std::string read_vehicle(const toml::table& v, VehicleGeometry& g, ForceCurve& curve) {
    for (const auto& [key, _] : v)
        if (key.str() != "mass_kg" && key.str() != "inertia_kg_m2" && key.str() != "thrust_forward_n" &&
            key.str() != "thrust_reverse_n")
            return "vehicle." + std::string(key.str()) +
                   ": unknown key; known keys: mass_kg, inertia_kg_m2, thrust_forward_n, thrust_reverse_n";
    if (const toml::node* n = v.get("mass_kg")) {
        const auto m = n->value<double>();
        if (!m || !std::isfinite(*m) || *m <= 0 || *m > 10000)
            return "vehicle.mass_kg: must be the vehicle's mass in kg, above 0 and at most 10000";
        g.mass_kg = *m;
    }
    if (const toml::node* n = v.get("inertia_kg_m2")) {
        Vec3 i;
        if (!triple(n, 10000, i) || i.x <= 0 || i.y <= 0 || i.z <= 0)
            return "vehicle.inertia_kg_m2: must be 3 moments of inertia in kg m^2 about x forward, y left, z up, each "
                   "above 0";
        g.inertia_kg_m2 = i;
    }
    std::vector<double> forward{0.0, kBtd150ForwardN}, reverse{0.0, kBtd150ReverseN};
    if (std::string e = read_curve(v, "thrust_forward_n", forward); !e.empty())
        return e;
    if (std::string e = read_curve(v, "thrust_reverse_n", reverse); !e.empty())
        return e;
    curve = ForceCurve(forward, reverse);
    return "";
}

// The [[thruster]] tables' position and direction: all eight placed, or none (the default).
std::string read_placements(const toml::table& root, std::array<ThrusterPlacement, kMotorCount>& out) {
    const toml::array* arr = root["thruster"].as_array();
    if (!arr)
        return "";
    std::size_t placed = 0;
    std::array<ThrusterPlacement, kMotorCount> p = out;
    for (std::size_t i = 0; i < arr->size(); ++i) {
        const toml::table* t = (*arr)[i].as_table();
        if (!t || (!t->contains("position") && !t->contains("direction")))
            continue;
        const std::string where = "thruster[" + std::to_string(i) + "].";
        if (arr->size() != kMotorCount)
            return where + "position: the vehicle is described by exactly 8 [[thruster]] tables, got " +
                   std::to_string(arr->size());
        if (!triple(t->get("position"), kMaxOffsetM, p[i].position))
            return where + "position: must be 3 numbers, metres from the centre of mass (x forward, y left, z up), "
                           "each within 10";
        Vec3 d;
        const double len = triple(t->get("direction"), 1e6, d) ? std::hypot(d.x, d.y, d.z) : 0.0;
        if (!(len > 1e-9))
            return where + "direction: must be 3 numbers (x forward, y left, z up), not all 0: the way a positive "
                           "motor value pushes";
        p[i].direction = {d.x / len, d.y / len, d.z / len};
        ++placed;
    }
    if (placed != 0 && placed != kMotorCount)
        return "thruster: position and direction are given for " + std::to_string(placed) +
               " of the 8 thrusters; give them for every thruster or for none";
    out = p;
    return "";
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

std::string VehicleGeometry::parse(const toml::table& root, VehicleGeometry& out) {
    VehicleGeometry g;
    ForceCurve curve;
    if (const toml::node* n = root.get("vehicle")) {
        const toml::table* v = n->as_table();
        if (!v)
            return "vehicle: must be a table ([vehicle])";
        if (std::string e = read_vehicle(*v, g, curve); !e.empty())
            return e;
    }
    std::array<ThrusterPlacement, kMotorCount> placements = g.placements_;
    if (std::string e = read_placements(root, placements); !e.empty())
        return e;
    VehicleGeometry made(placements, curve);
    made.mass_kg = g.mass_kg;
    made.inertia_kg_m2 = g.inertia_kg_m2;
    out = std::move(made);
    return "";
}

std::string VehicleGeometry::load(const std::string& path, VehicleGeometry& out) {
    std::ifstream in(path, std::ios::binary);
    if (!in)
        return path + ": cannot be read";
    std::stringstream ss;
    ss << in.rdbuf();
    // The guard every reader of this file has (core/toml_text.hpp says why).
    if (std::string e = non_ascii_outside_comments(ss.str()); !e.empty())
        return path + ": " + e;
    toml::table root;
    try {
        root = toml::parse(ss.str(), path);
    } catch (const toml::parse_error& e) {
        return path + ": line " + std::to_string(e.source().begin.line) + ": " + std::string(e.description());
    }
    if (std::string e = parse(root, out); !e.empty())
        return path + ": " + e;
    return "";
}

} // namespace caracara
