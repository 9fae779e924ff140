// caracara-ros: the vehicle as ROS 2 topics over DDS (Cyclone DDS), without ROS on the vehicle.
// One DDS participant named like a ROS 2 node's; a client of caracarad's D-Bus API and of nothing
// else (docs/ros2.md).
#include "drivers/sdbus/program_args.hpp"
#include "tools/ros/command_subscriber.hpp"
#include "tools/ros/spoken_distro.hpp"
#include "tools/ros/telemetry_publisher.hpp"

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <unistd.h>
#include <iostream>
#include <systemd/sd-daemon.h>

namespace {

constexpr const char* kDefaultConfig = caracara::ros::kDefaultConfigPath;

void help() {
    std::cout << "caracara-ros [OPTIONS...]\n\n"
                 "Publish caracarad (org.caracara.Vehicle1) as ROS 2 topics over DDS and take commands\n"
                 "from them when the config allows (docs/ros2.md).\n\n"
                 "  --config FILE    The settings (default " << kDefaultConfig << "; a missing default is no error)\n"
                 "  --commands       Take cmd_wrench and cmd_thrust (the config's ros.commands = true)\n"
                 "  --system | --user | --bus-address ADDR   The bus caracarad is on (default: system)\n"
                 "  -h --help        Show this help\n"
                 "  --version        Show the version\n"
                 "ROS_DOMAIN_ID picks the DDS domain unless the config names one.\n";
}


// Kill() on the reading connection, sent at once. Without one (caracarad restarting, the
// connection being made again) on a connection of its own, so a kill is never dropped.
void kill_over(sd_bus* bus, const caracara::dbus::BusChoice& choice) {
    caracara::dbus::BusPtr own;
    if (!bus) {
        if (const int r = caracara::dbus::open_bus(choice, "caracara-ros-kill", own); r < 0) {
            std::fprintf(stderr, "caracara-ros: kill not sent: cannot reach the bus: %s\n", std::strerror(-r));
            return;
        }
        bus = own.get();
    }
    sd_bus_message* m = nullptr;
    if (sd_bus_message_new_method_call(bus, &m, caracara::dbus::kBusName, caracara::dbus::kRootPath,
                                       caracara::dbus::kVehicleIface, "Kill") < 0)
        return;
    sd_bus_message_set_auto_start(m, 0);
    const int r = sd_bus_call_async(bus, nullptr, m, nullptr, nullptr, 0);
    sd_bus_message_unref(m);
    if (r < 0)
        std::fprintf(stderr, "caracara-ros: kill not sent: %s\n", std::strerror(-r));
    sd_bus_flush(bus); // now, not at the next turn of the loop; on its own connection, before it closes
}

} // namespace

int main(int argc, char** argv) {
    caracara::ros::RosConfig config;
    if (const char* d = std::getenv("ROS_DOMAIN_ID"); d && *d)
        config.domain_id = static_cast<uint32_t>(std::strtoul(d, nullptr, 10));
    std::string config_path = kDefaultConfig;
    bool config_given = false, commands_flag = false;
    caracara::dbus::ProgramArgs args("caracara-ros", CARACARA_VERSION, argc, argv, help);
    while (args.next(config.bus)) {
        if (args.is("--config")) {
            config_path = args.value();
            config_given = true;
        } else if (args.flag("--commands")) {
            commands_flag = true;
        } else {
            args.unknown();
        }
    }
    if (config_given || access(config_path.c_str(), F_OK) == 0)
        if (const std::string e = caracara::ros::load_config(config_path, config); !e.empty())
            args.usage_error(e);
    config.commands = config.commands || commands_flag;
    if (const std::string e = caracara::ros::commands_refusal(config, caracara::ros::is_loopback(config.interface));
        !e.empty()) {
        std::fprintf(stderr, "caracara-ros: %s\n", e.c_str());
        return 2;
    }

    caracara::EventPtr event;
    if (caracara::open_event_loop(event, {SIGTERM, SIGINT}) < 0)
        return 1;
    try {
        caracara::ros::DdsParticipant dds(config);
        caracara::ros::CommandRecord record; // the writers' holder and refusals, on /diagnostics
        caracara::ros::SpokenDistro distro{config.range_layout, config.range_layout_given
                                                                    ? "range_layout in the config"
                                                                    : "no ROS 2 peer seen yet: Humble's until one is"};
        caracara::ros::TelemetryPublisher telemetry(event.get(), dds, config, record, distro);
        caracara::ros::CommandSubscriber commands(event.get(), dds, config, record, distro,
                                                  [&] { kill_over(telemetry.bus(), config.bus); });
        telemetry.start();
        dds.watch(event.get());
        std::fprintf(stderr, "caracara-ros: domain %u, namespace %s, commands %s, DDS Security %s%s\n", config.domain_id,
                     config.ros_namespace.empty() ? "/" : config.ros_namespace.c_str(), config.commands ? "on" : "off",
                     config.security.empty() ? "off" : "on, enclave ", config.security.c_str());
        if (config.commands && config.wrench_units == caracara::ros::WrenchUnits::Newton)
            std::fprintf(stderr, "caracara-ros: cmd_wrench in newtons and newton-metres, through the vehicle %s "
                                 "describes\n", config.vehicle_config.c_str());
        if (config.commands && config.security.empty() && !caracara::ros::is_loopback(config.interface))
            std::fprintf(stderr, "caracara-ros: warning: commands from anyone who reaches interface %s: no DDS Security "
                                 "(ros.insecure_commands = true)\n", config.interface.empty() ? "(any)" : config.interface.c_str());
        sd_notify(0, "READY=1");
        const int r = sd_event_loop(event.get());
        sd_notify(0, "STOPPING=1");
        return r < 0 ? 1 : 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "caracara-ros: %s\n", e.what());
        return 1;
    }
}
