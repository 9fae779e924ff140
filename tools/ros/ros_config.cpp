#include "tools/ros/ros_config.hpp"

#include <cctype>
#include <cmath>
#include <numbers>
#include <toml++/toml.h>

namespace caracara::ros {

namespace {

// A boolean key: true or false, anything else refused by name (a string "false" is not false).
std::string read_bool(const std::string& path, const toml::node_view<toml::node>& ros, const char* key, bool& out) {
    const toml::node* n = ros[key].node();
    if (!n)
        return "";
    if (const auto v = n->value_exact<bool>()) {
        out = *v;
        return "";
    }
    return path + ": ros." + key + " must be true or false";
}

// Bounds of a mount that no vehicle of this size exceeds: a typo (mm for m, degrees for
// radians) is refused rather than drawn metres away in RViz.
constexpr double kMaxMountOffsetM = 10.0;
constexpr double kMaxMountAngleRad = 2 * std::numbers::pi;

// A frame name tf2 takes: letters, digits and _ (no leading /, which tf2 refuses).
bool frame_name_ok(const std::string& f) {
    if (f.empty())
        return false;
    for (const char ch : f)
        if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '_')
            return false;
    return true;
}

// Three finite numbers, each within `limit`, into `out`; false otherwise.
bool read_triple(const toml::node* n, double limit, frames::Vec3& out) {
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

// One [ros.imu] or [[ros.range]] table (`name` as the errors call it) into `m`.
std::string read_mount(const std::string& path, const std::string& name, const toml::node& node, SensorMount& m) {
    const toml::table* t = node.as_table();
    if (!t)
        return path + ": " + name + " must be a table (frame, xyz, rpy)";
    for (const auto& [key, _] : *t)
        if (key.str() != "frame" && key.str() != "xyz" && key.str() != "rpy")
            return path + ": unknown key " + name + "." + std::string(key.str());
    if (const toml::node* f = t->get("frame")) {
        const auto v = f->value_exact<std::string>();
        if (!v || !frame_name_ok(*v))
            return path + ": " + name + ".frame must be a frame name (letters, digits, _)" + (v ? " (\"" + *v + "\")" : "");
        m.frame = *v;
    }
    if (t->contains("xyz") && !read_triple(t->get("xyz"), kMaxMountOffsetM, m.xyz))
        return path + ": " + name + ".xyz must be 3 numbers, metres from the base frame (x forward, y left, z up), each within 10";
    if (t->contains("rpy") && !read_triple(t->get("rpy"), kMaxMountAngleRad, m.rpy))
        return path + ": " + name + ".rpy must be 3 numbers, radians (roll, pitch, yaw about x, y, z), each within 2 pi";
    return "";
}

} // namespace

SensorMount range_mount(const RosConfig& c, std::size_t i) {
    return i < c.ranges.size() ? c.ranges[i] : SensorMount{range_frame(i), {}, {}};
}

std::string load_config(const std::string& path, RosConfig& c) {
    toml::table t;
    try {
        t = toml::parse_file(path);
    } catch (const toml::parse_error& e) {
        return path + ": " + std::string(e.description());
    }
    for (const auto& [key, _] : t)
        if (key.str() != "ros" && key.str() != "network")
            return path + ": unknown table [" + std::string(key.str()) + "]";
    const auto ros = t["ros"];
    for (const auto& [key, _] : ros.as_table() ? *ros.as_table() : toml::table{}) {
        static const char* const known[] = {"namespace", "domain_id", "range_layout", "commands", "world_frame",
                                            "base_frame", "frame_convention", "publish_odom_tf", "range_min_m",
                                            "range_max_m", "range_fov_rad", "sensor_rate_hz", "imu", "range"};
        bool ok = false;
        for (const char* k : known)
            ok = ok || key.str() == k;
        if (!ok)
            return path + ": unknown key ros." + std::string(key.str());
    }
    if (auto v = ros["namespace"].value<std::string>()) {
        if (v->empty() || (*v)[0] != '/')
            return path + ": ros.namespace must start with / (\"" + *v + "\")";
        c.ros_namespace = *v == "/" ? "" : *v;
    }
    if (auto v = ros["domain_id"].value<int64_t>()) {
        if (*v < 0 || *v > 232) // the RTPS port formula's limit, as ROS_DOMAIN_ID's documentation says
            return path + ": ros.domain_id must be 0..232";
        c.domain_id = static_cast<uint32_t>(*v);
    }
    if (auto v = ros["range_layout"].value<std::string>()) {
        c.range_layout_given = true;
        if (*v == "humble")
            c.range_layout = RangeLayout::Humble;
        else if (*v == "jazzy")
            c.range_layout = RangeLayout::Jazzy;
        else
            return path + ": ros.range_layout must be \"humble\" or \"jazzy\" (\"" + *v + "\")";
    }
    if (std::string e = read_bool(path, ros, "commands", c.commands); !e.empty())
        return e;
    if (auto v = ros["world_frame"].value<std::string>())
        c.world_frame = *v;
    if (auto v = ros["base_frame"].value<std::string>())
        c.base_frame = *v;
    if (const toml::node* n = ros["frame_convention"].node()) {
        const auto v = n->value_exact<std::string>();
        const auto f = v ? parse_name<frames::WorldFrame>(*v) : std::nullopt;
        if (!f)
            return path + ": ros.frame_convention must be \"enu\" or \"ned\"" + (v ? " (\"" + *v + "\")" : "");
        c.frame_convention = *f;
    }
    if (std::string e = read_bool(path, ros, "publish_odom_tf", c.publish_odom_tf); !e.empty())
        return e;
    if (auto v = ros["range_min_m"].value<double>())
        c.range_min_m = static_cast<float>(*v);
    if (auto v = ros["range_max_m"].value<double>())
        c.range_max_m = static_cast<float>(*v);
    if (auto v = ros["range_fov_rad"].value<double>())
        c.range_fov_rad = static_cast<float>(*v);
    if (const toml::node* n = ros["sensor_rate_hz"].node()) {
        const auto v = n->value<double>(); // an integer is taken too
        if (!v || !std::isfinite(*v) || *v <= 0 || *v > kMaxSensorRateHz)
            return path + ": ros.sensor_rate_hz must be a number of Hz above 0 and at most " +
                   std::to_string(static_cast<int>(kMaxSensorRateHz));
        c.sensor_rate_hz = *v;
    }
    if (const toml::node* n = ros["imu"].node())
        if (std::string e = read_mount(path, "ros.imu", *n, c.imu); !e.empty())
            return e;
    if (const toml::node* n = ros["range"].node()) {
        const toml::array* a = n->as_array();
        if (!a)
            return path + ": ros.range must be an array of tables ([[ros.range]], one per distance sensor)";
        c.ranges.clear();
        for (std::size_t i = 0; i < a->size(); ++i) {
            SensorMount m{range_frame(i), {}, {}};
            if (std::string e = read_mount(path, "ros.range[" + std::to_string(i) + "]", (*a)[i], m); !e.empty())
                return e;
            c.ranges.push_back(m);
        }
    }
    // One parent per frame in tf2's tree: no sensor frame may be another's or the vehicle's own.
    std::vector<std::string> names{c.imu.frame};
    for (const SensorMount& m : c.ranges)
        names.push_back(m.frame);
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (names[i] == c.base_frame || names[i] == c.world_frame)
            return path + ": sensor frame \"" + names[i] + "\" is the vehicle's own (base_frame or world_frame)";
        for (std::size_t k = 0; k < i; ++k)
            if (names[k] == names[i])
                return path + ": sensor frame \"" + names[i] + "\" is named twice";
    }
    if (auto v = t["network"]["interface"].value<std::string>())
        c.interface = *v;
    return "";
}

std::string ros_topic(const RosConfig& c, const std::string& name) {
    return name.starts_with('/') ? name : c.ros_namespace + "/" + name;
}

} // namespace caracara::ros
