#include "tools/ros/ros_config.hpp"

#include "tests/catch.hpp"

#include <cstdlib>
#include <unistd.h>

using caracara::ros::commands_refusal;
using caracara::ros::RosConfig;

TEST_CASE("commands without DDS Security are refused off loopback, unless insecure_commands says so") {
    RosConfig c;
    c.commands = true;
    c.interface = "eth1";
    SECTION("a tether with no security: refused, naming the interface and both ways out") {
        const std::string e = commands_refusal(c, false);
        CHECK(e.find("interface eth1") != std::string::npos);
        CHECK(e.find("ros.security") != std::string::npos);
        CHECK(e.find("ros.insecure_commands = true") != std::string::npos);
    }
    SECTION("no interface named (Cyclone picks any): refused") {
        c.interface.clear();
        CHECK_FALSE(commands_refusal(c, false).empty());
    }
    SECTION("with an enclave: taken") {
        c.security = "/etc/caracara/keystore/enclaves/caracara/ros";
        CHECK(commands_refusal(c, false).empty());
    }
    SECTION("on loopback: taken (nobody off the machine reaches it)") {
        c.interface = "lo";
        CHECK(commands_refusal(c, true).empty());
    }
    SECTION("insecure_commands = true in so many words: taken") {
        c.insecure_commands = true;
        CHECK(commands_refusal(c, false).empty());
    }
    SECTION("commands off: nothing to refuse") {
        c.commands = false;
        CHECK(commands_refusal(c, false).empty());
    }
}

TEST_CASE("the default settings may run: commands off, loopback") {
    const RosConfig c;
    CHECK(commands_refusal(c, false).empty());
    CHECK(c.interface == "lo");
    CHECK_FALSE(c.insecure_commands);
    CHECK(c.security.empty());
}

namespace {
// The settings read from `text` as caracara-ros reads its file: "" or the message.
std::string load(const std::string& text, RosConfig& c) {
    char path[] = "/tmp/caracara-ros-config-XXXXXX";
    const int fd = ::mkstemp(path);
    REQUIRE(fd >= 0);
    REQUIRE(::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()));
    ::close(fd);
    const std::string e = caracara::ros::load_config(path, c);
    ::unlink(path);
    return e;
}
} // namespace

TEST_CASE("values beyond their types: names ROS takes, distances a Range carries, an interface name (fuzz_ros_config)") {
    RosConfig c;
    CHECK(load("[ros]\nnamespace = \"/sub/caracara_1\"\nbase_frame = \"caracara/base_link\"\n", c).empty());
    CHECK(c.ros_namespace == "/sub/caracara_1");
    for (const char* bad : {"[ros]\nnamespace = \"/a b\"\n", "[ros]\nnamespace = \"/a//b\"\n", "[ros]\nnamespace = \"/a/\"\n",
                            "[ros]\nnamespace = \"/1a\"\n", "[ros]\nworld_frame = \"\"\n", "[ros]\nbase_frame = \"/base\"\n",
                            "[ros]\nworld_frame = \"odom\"\nbase_frame = \"odom\"\n", "[ros]\nrange_min_m = 5.0\nrange_max_m = 1.0\n",
                            "[ros]\nrange_max_m = nan\n", "[ros]\nrange_fov_rad = 4.0\n",
                            "[network]\ninterface = \"a-name-longer-than-15\"\n", "[network]\ninterface = \"eth0:1\"\n",
                            "[ros]\nnamespace = \"/caracara\"\u03fb\n"}) {
        RosConfig d;
        const std::string e = load(bad, d);
        INFO(bad);
        CHECK(e.starts_with("/tmp/caracara-ros-config-"));
        CHECK(e.find(": ") != std::string::npos);
    }
}

TEST_CASE("wrench_units: fractions by default, newtons through the vehicle's description, anything else named") {
    RosConfig c;
    CHECK(load("[ros]\n", c).empty());
    CHECK(c.wrench_units == caracara::ros::WrenchUnits::Fraction);
    // The description is the daemon's file: [vehicle] and the [[thruster]] tables.
    char vehicle[] = "/tmp/caracara-vehicle-XXXXXX";
    const int fd = ::mkstemp(vehicle);
    REQUIRE(fd >= 0);
    const std::string text = "[vehicle]\nmass_kg = 11.5\nthrust_reverse_n = [0, 12]\n";
    REQUIRE(::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()));
    ::close(fd);
    RosConfig n;
    CHECK(load("[ros]\nwrench_units = \"newton\"\nvehicle_config = \"" + std::string(vehicle) + "\"\n", n).empty());
    CHECK(n.wrench_units == caracara::ros::WrenchUnits::Newton);
    CHECK(*n.vehicle.mass_kg == 11.5);
    CHECK(n.vehicle.curve().full_n(true) == 12.0);
    ::unlink(vehicle);
    RosConfig bad;
    CHECK(load("[ros]\nwrench_units = \"newtons\"\n", bad).find("ros.wrench_units must be \"fraction\" or \"newton\" (\"newtons\")") != std::string::npos);
    CHECK(bad.wrench_units == caracara::ros::WrenchUnits::Fraction);
    CHECK(load("[ros]\nvehicle_config = \"caracarad.toml\"\n", bad).find("ros.vehicle_config must be the absolute path") !=
          std::string::npos);
    // Newtons with no description to read: named, with the file.
    const std::string e = load("[ros]\nwrench_units = \"newton\"\nvehicle_config = \"/nonexistent/caracarad.toml\"\n", bad);
    CHECK(e.find("ros.wrench_units = \"newton\" needs the vehicle's description: /nonexistent/caracarad.toml: cannot be "
                 "read") != std::string::npos);
}
