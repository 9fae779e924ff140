#include "core/vehicle_config.hpp"

#include "core/toml_text.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

namespace caracara {

namespace {

using frames::Vec3;

constexpr double kMaxOffsetM = 10.0; // as a sensor's mount: a typo (mm for m) is refused

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
        if (!read_triple(n, 10000, i) || i.x <= 0 || i.y <= 0 || i.z <= 0)
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
        if (!read_triple(t->get("position"), kMaxOffsetM, p[i].position))
            return where + "position: must be 3 numbers, metres from the centre of mass (x forward, y left, z up), "
                           "each within 10";
        Vec3 d;
        const double len = read_triple(t->get("direction"), 1e6, d) ? std::hypot(d.x, d.y, d.z) : 0.0;
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

bool read_triple(const toml::node* n, double limit, Vec3& out) {
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

std::string parse_vehicle(const toml::table& root, VehicleGeometry& out) {
    VehicleGeometry g;
    ForceCurve curve;
    if (const toml::node* n = root.get("vehicle")) {
        const toml::table* v = n->as_table();
        if (!v)
            return "vehicle: must be a table ([vehicle])";
        if (std::string e = read_vehicle(*v, g, curve); !e.empty())
            return e;
    }
    std::array<ThrusterPlacement, kMotorCount> placements = g.placements();
    if (std::string e = read_placements(root, placements); !e.empty())
        return e;
    VehicleGeometry made(placements, curve);
    made.mass_kg = g.mass_kg;
    made.inertia_kg_m2 = g.inertia_kg_m2;
    out = std::move(made);
    return "";
}

std::string load_vehicle(const std::string& path, VehicleGeometry& out) {
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
    if (std::string e = parse_vehicle(root, out); !e.empty())
        return path + ": " + e;
    return "";
}

} // namespace caracara
