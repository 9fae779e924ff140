#include "tools/ros/ros_config.hpp"

#include "tests/catch.hpp"

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
