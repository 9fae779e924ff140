// caracara-ros's settings (tools/ros/ros_config.hpp) read from arbitrary text. Invariants: an
// accepted file gives a namespace and frame names that ROS 2 and tf2 take, a domain the RTPS
// port formula takes, distances and a field of view a Range can carry, an interface name the
// kernel could have, an enclave as an absolute path; commands without security off loopback
// are refused unless insecure_commands says otherwise; every topic name built from it is a ROS
// name. A refused file gives a message that starts with the file's path and names the key.
#include "fuzz/check.hpp"
#include "tools/ros/ros_config.hpp"

#include <cctype>
#include <cmath>
#include <net/if.h>
#include <string>
#include <string_view>
#include <sys/mman.h>
#include <unistd.h>

using namespace caracara;

namespace {

bool token(std::string_view t) {
    if (t.empty() || !(std::isalpha(static_cast<unsigned char>(t[0])) || t[0] == '_'))
        return false;
    for (const char c : t)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_')
            return false;
    return true;
}

// A ROS 2 name ("Topic and service name mapping to DDS"): "/" then tokens joined by single "/".
bool ros_name(std::string_view n) {
    if (!n.starts_with('/') || n.size() < 2 || n.ends_with('/'))
        return false;
    n.remove_prefix(1);
    for (std::size_t at = 0;;) {
        const auto end = n.find('/', at);
        if (!token(n.substr(at, end == std::string_view::npos ? end : end - at)))
            return false;
        if (end == std::string_view::npos)
            return true;
        at = end + 1;
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
    static const int fd = ::memfd_create("ros.toml", 0);
    FUZZ_CHECK(fd >= 0, "memfd_create");
    FUZZ_CHECK(::ftruncate(fd, 0) == 0 && ::pwrite(fd, data, size, 0) == static_cast<ssize_t>(size), "write");
    const std::string path = "/proc/self/fd/" + std::to_string(fd);

    ros::RosConfig c;
    const std::string error = ros::load_config(path, c);
    if (!error.empty()) {
        FUZZ_CHECK(error.starts_with(path + ": ") && error.size() > path.size() + 2, "message %s", error.c_str());
        return 0;
    }
    FUZZ_CHECK(c.ros_namespace.empty() || ros_name(c.ros_namespace), "namespace \"%s\"", c.ros_namespace.c_str());
    FUZZ_CHECK(c.domain_id <= 232, "domain %u", c.domain_id);
    // tf2's frame ids: a ROS name without its leading "/" ("base_link", "caracara/base_link").
    FUZZ_CHECK(ros_name("/" + c.world_frame) && ros_name("/" + c.base_frame), "frames \"%s\" \"%s\"",
               c.world_frame.c_str(), c.base_frame.c_str());
    FUZZ_CHECK(c.world_frame != c.base_frame, "one frame for the world and the body: %s", c.world_frame.c_str());
    FUZZ_CHECK(std::isfinite(c.range_min_m) && std::isfinite(c.range_max_m) && c.range_min_m >= 0.0f &&
                   c.range_min_m < c.range_max_m,
               "range %g..%g", c.range_min_m, c.range_max_m);
    FUZZ_CHECK(std::isfinite(c.range_fov_rad) && c.range_fov_rad >= 0.0f && c.range_fov_rad <= static_cast<float>(M_PI),
               "field of view %g", c.range_fov_rad);
    FUZZ_CHECK(c.interface.size() < IFNAMSIZ && c.interface.find_first_of("/ \t\n\r:") == std::string::npos &&
                   c.interface.find('\0') == std::string::npos,
               "interface \"%s\"", c.interface.c_str());
    FUZZ_CHECK(c.security.empty() || (c.security.starts_with('/') && c.security.find('\0') == std::string::npos),
               "security \"%s\"", c.security.c_str());
    for (const char* topic : {"state", "imu", "cmd_wrench", "/diagnostics"})
        FUZZ_CHECK(ros_name(ros::ros_topic(c, topic)), "topic %s under \"%s\"", topic, c.ros_namespace.c_str());
    const bool open = c.commands && c.security.empty() && !c.insecure_commands;
    FUZZ_CHECK(ros::commands_refusal(c, false).empty() != open, "commands off loopback: refusal \"%s\"",
               ros::commands_refusal(c, false).c_str());
    FUZZ_CHECK(ros::commands_refusal(c, true).empty(), "commands on loopback refused");
    return 0;
}
