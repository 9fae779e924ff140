#include "tools/ros/ros_config.hpp"

#include "core/toml_text.hpp"
#include "core/vehicle_config.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <ifaddrs.h>
#include <iterator>
#include <net/if.h>
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

bool token(std::string_view t) {
    if (t.empty() || !(std::isalpha(static_cast<unsigned char>(t[0])) || t[0] == '_'))
        return false;
    return std::all_of(t.begin(), t.end(), [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_'; });
}

// Tokens joined by single "/" ("caracara/base_link"), as a ROS 2 name after its leading "/"
// ("Topic and service name mapping to DDS"): what tf2 and the graph take.
bool relative_name(std::string_view n) {
    for (std::size_t at = 0;;) {
        const auto end = n.find('/', at);
        if (!token(n.substr(at, end == std::string_view::npos ? end : end - at)))
            return false;
        if (end == std::string_view::npos)
            return true;
        at = end + 1;
    }
}

// What the file's values must be beyond their types: names ROS takes, distances a Range can
// carry, an interface name the kernel could have (found by the fuzz harness, fuzz_ros_config).
std::string check_values(const std::string& path, const RosConfig& c) {
    if (!c.ros_namespace.empty() && !relative_name(std::string_view(c.ros_namespace).substr(1)))
        return path + ": ros.namespace must be a ROS name: / then words of letters, digits and _ joined by / (\"" +
               c.ros_namespace + "\")";
    for (const auto& [key, frame] : {std::pair{"world_frame", &c.world_frame}, std::pair{"base_frame", &c.base_frame}})
        if (!relative_name(*frame))
            return path + ": ros." + key + " must be a frame name: words of letters, digits and _ joined by / (\"" +
                   *frame + "\")";
    if (c.world_frame == c.base_frame)
        return path + ": ros.world_frame and ros.base_frame are the same frame (\"" + c.world_frame + "\")";
    if (!std::isfinite(c.range_min_m) || !std::isfinite(c.range_max_m) || c.range_min_m < 0.0f ||
        c.range_min_m >= c.range_max_m)
        return path + ": ros.range_min_m and ros.range_max_m must be distances with 0 <= min < max";
    if (!std::isfinite(c.range_fov_rad) || c.range_fov_rad < 0.0f || c.range_fov_rad > static_cast<float>(M_PI))
        return path + ": ros.range_fov_rad must be 0..pi";
    if (c.interface.size() >= IFNAMSIZ || c.interface.find_first_of(std::string_view("/ \t\n\r:\0", 7)) != std::string::npos)
        return path + ": network.interface is not an interface name (\"" + c.interface + "\")";
    if (c.security.find('\0') != std::string::npos || c.security_plugins.find('\0') != std::string::npos)
        return path + ": ros.security and ros.security_plugins must be paths";
    return "";
}

// Bounds of a mount that no vehicle of this size exceeds: a typo (mm for m, degrees for
// radians) is refused rather than drawn metres away in RViz.
constexpr double kMaxMountOffsetM = 10.0;
constexpr double kMaxMountAngleRad = 2 * std::numbers::pi;

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
        if (!v || !relative_name(*v))
            return path + ": " + name + ".frame must be a frame name (words of letters, digits and _ joined by /)" + (v ? " (\"" + *v + "\")" : "");
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

std::vector<SensorMount> sensor_mounts(const RosConfig& c, std::size_t ranges) {
    std::vector<SensorMount> mounts{c.imu};
    for (std::size_t i = 0; i < std::max(c.ranges.size(), ranges); ++i)
        mounts.push_back(range_mount(c, i));
    return mounts;
}

frames::Quaternion mount_rotation(const SensorMount& m) { return frames::from_euler_zyx(m.rpy.z, m.rpy.y, m.rpy.x); }

std::string load_config(const std::string& path, RosConfig& c) {
    std::ifstream in(path, std::ios::binary);
    if (!in)
        return path + ": cannot be read";
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    // The guard caracarad's and the simulator's readers have (core/toml_text.hpp says why); its
    // absence here was found by fuzz_ros_config.
    if (std::string e = non_ascii_outside_comments(text); !e.empty())
        return path + ": " + e;
    toml::table t;
    try {
        t = toml::parse(text, path);
    } catch (const toml::parse_error& e) {
        return path + ": line " + std::to_string(e.source().begin.line) + ": " + std::string(e.description());
    }
    for (const auto& [key, _] : t)
        if (key.str() != "ros" && key.str() != "network")
            return path + ": unknown table [" + std::string(key.str()) + "]";
    const auto ros = t["ros"];
    for (const auto& [key, _] : ros.as_table() ? *ros.as_table() : toml::table{}) {
        static const char* const known[] = {"namespace", "domain_id", "range_layout", "commands", "world_frame",
                                            "base_frame", "frame_convention", "publish_odom_tf", "range_min_m",
                                            "range_max_m", "range_fov_rad", "security", "security_plugins", "insecure_commands",
                                            "sensor_rate_hz", "imu", "range", "wrench_units", "vehicle_config"};
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
    // value_exact: toml++ 3.3's value<int64_t>() of a float casts it unchecked, undefined past
    // int64's range (fuzz_ros_config); a float domain is refused instead.
    if (const toml::node* n = ros["domain_id"].node()) {
        const auto v = n->value_exact<int64_t>();
        if (!v || *v < 0 || *v > 232) // the RTPS port formula's limit, as ROS_DOMAIN_ID's documentation says
            return path + ": ros.domain_id must be an integer 0..232";
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
    if (std::string e = read_bool(path, ros, "insecure_commands", c.insecure_commands); !e.empty())
        return e;
    if (const toml::node* n = ros["security"].node()) {
        const auto v = n->value_exact<std::string>();
        if (!v || v->empty() || (*v)[0] != '/')
            return path + ": ros.security must be the absolute path of an SROS2 enclave directory" +
                   (v ? " (\"" + *v + "\")" : "");
        c.security = *v;
    }
    if (auto v = ros["security_plugins"].value<std::string>())
        c.security_plugins = *v;
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
    if (const toml::node* n = ros["wrench_units"].node()) {
        const auto v = n->value_exact<std::string>();
        const auto u = v ? parse_name<WrenchUnits>(*v) : std::nullopt;
        if (!u)
            return path + ": ros.wrench_units must be \"fraction\" or \"newton\"" + (v ? " (\"" + *v + "\")" : "");
        c.wrench_units = *u;
    }
    if (const toml::node* n = ros["vehicle_config"].node()) {
        const auto v = n->value_exact<std::string>();
        if (!v || v->empty() || (*v)[0] != '/')
            return path + ": ros.vehicle_config must be the absolute path of the caracarad.toml that describes the "
                          "vehicle" + (v ? " (\"" + *v + "\")" : "");
        c.vehicle_config = *v;
    }
    if (c.wrench_units == WrenchUnits::Newton)
        if (std::string e = load_vehicle(c.vehicle_config, c.vehicle); !e.empty())
            return path + ": ros.wrench_units = \"newton\" needs the vehicle's description: " + e;
    return check_values(path, c);
}

std::string commands_refusal(const RosConfig& c, bool loopback) {
    if (!c.commands || !c.security.empty() || loopback || c.insecure_commands)
        return "";
    // Plain DDS authenticates nobody: anyone who reaches the interface could drive the vehicle.
    return "commands are refused without DDS Security on interface " +
           (c.interface.empty() ? std::string("(any: none named)") : c.interface) +
           ": set ros.security to an SROS2 enclave (docs/ros2.md), or ros.insecure_commands = true to let anyone "
           "on that network drive";
}

bool is_loopback(const std::string& interface) {
    ifaddrs* all = nullptr;
    if (interface.empty() || getifaddrs(&all) != 0)
        return false;
    bool loopback = false, found = false;
    for (const ifaddrs* a = all; a; a = a->ifa_next)
        if (a->ifa_name && interface == a->ifa_name) {
            found = true;
            loopback = (a->ifa_flags & IFF_LOOPBACK) != 0;
            break;
        }
    freeifaddrs(all);
    return found && loopback;
}

std::string ros_topic(const RosConfig& c, const std::string& name) {
    return name.starts_with('/') ? name : c.ros_namespace + "/" + name;
}

} // namespace caracara::ros
