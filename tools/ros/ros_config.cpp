#include "tools/ros/ros_config.hpp"

#include <cmath>
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

} // namespace

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
                                            "range_max_m", "range_fov_rad", "sensor_rate_hz"};
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
    if (auto v = t["network"]["interface"].value<std::string>())
        c.interface = *v;
    return "";
}

std::string ros_topic(const RosConfig& c, const std::string& name) {
    return name.starts_with('/') ? name : c.ros_namespace + "/" + name;
}

} // namespace caracara::ros
