// caracara-sim: plays the Caracara vehicle's hardware for caracarad (device protocol on a
// Unix socket) and for people and tests (org.caracara.Simulator1 on D-Bus).
#include "core/dive_format.hpp"
#include "drivers/platform/dive_files.hpp"
#include "drivers/platform/io_error.hpp"
#include "drivers/sdbus/program_args.hpp"
#include "drivers/sdbus/sdbus.hpp"
#include "sim/device_server.hpp"
#include "sim/dive_replay.hpp"
#include "sim/inspector.hpp"
#include "sim/kernel_bridge.hpp"
#include "sim/sim_config.hpp"
#include "sim/sim_vehicle.hpp"

#include <csignal>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>
#include <string>
#include <systemd/sd-daemon.h>
#include <ctime>
#include <unistd.h>

using namespace caracara;
using namespace caracara::sim;

namespace {

void usage(FILE* f) {
    std::fputs("Usage: caracara-sim [OPTIONS]\n"
               "Simulated Caracara vehicle: serves the device protocol for caracarad --hardware=sim:SOCKET.\n\n"
               "  --socket PATH         device socket to serve (default /run/caracara/sim.sock)\n"
               "  --kernel-bridge DEV   also serve the test kernel module's bridge device (tests/kernel):\n"
               "                        caracarad then runs --hardware=linux on the kernel's own nodes;\n"
               "                        the device socket is served only if --socket is given\n"
               "  --config FILE         vehicle description (TOML; [i2c], [spi], [[thruster]], [sim])\n"
               "  --config-if-exists FILE  the same, but the built-in vehicle when FILE does not exist\n"
               "                        (caracara-sim.service: caracarad's file, absent on defaults)\n"
               "  --system              inspection API on the system bus\n"
               "  --user                inspection API on the user bus (default)\n"
               "  --bus-address ADDR    inspection API on the bus at ADDR\n"
               "  --no-dbus             no inspection API\n"
               "  --realistic-timing    really wait the wire time of every transaction\n"
               "  --clock-hz HZ         I2C clock (default 100000)\n"
               "  --physics-hz HZ       model update rate (default 100)\n"
               "  --replay DIVE         the thrusters and the Teensy answer with a recorded dive's\n"
               "                        status and orientation, from caracarad's ClearKill on\n"
               "                        (docs/dive-format.md)\n"
               "  --version             the version, and exit\n"
               "  -h, --help            this text\n",
               f);
}

struct Physics {
    SimVehicle* vehicle;
    uint64_t last_us = 0;
    uint64_t period_us = 10000;
};

int on_physics(sd_event_source* s, uint64_t usec, void* userdata) {
    auto* p = static_cast<Physics*>(userdata);
    const double dt = p->last_us ? static_cast<double>(usec - p->last_us) / 1e6 : 0.0;
    p->last_us = usec;
    p->vehicle->step(dt, usec * 1000);
    sd_event_source_set_time(s, usec + p->period_us);
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    std::string socket_path = "/run/caracara/sim.sock";
    std::string config_path;
    bool config_optional = false;
    std::string kernel_bridge;
    bool socket_given = false;
    dbus::BusChoice bus_choice{dbus::BusChoice::Kind::User, {}};
    bool use_dbus = true;
    int realistic = -1;
    long clock_hz = 0;
    long physics_hz = 100;
    std::string replay_path;

    dbus::ProgramArgs args("caracara-sim", CARACARA_VERSION, argc, argv, [] { usage(stdout); });
    while (args.next(bus_choice)) {
        if (args.is("--socket")) { socket_path = args.value(); socket_given = true; }
        else if (args.is("--kernel-bridge")) kernel_bridge = args.value();
        else if (args.is("--config")) config_path = args.value();
        else if (args.is("--config-if-exists")) { config_path = args.value(); config_optional = true; }
        else if (args.flag("--no-dbus")) use_dbus = false;
        else if (args.is("--replay")) replay_path = args.value();
        else if (args.flag("--realistic-timing")) realistic = 1;
        else if (args.is("--clock-hz")) clock_hz = std::strtol(args.value().c_str(), nullptr, 10);
        else if (args.is("--physics-hz")) physics_hz = std::strtol(args.value().c_str(), nullptr, 10);
        else args.unknown();
    }
    if (physics_hz < 1 || physics_hz > 10000) {
        std::fprintf(stderr, "caracara-sim: --physics-hz must be 1..10000\n");
        return 2;
    }

    SimConfig cfg = default_sim_config();
    std::string err;
    // caracarad runs on the same built-in vehicle when its file is absent.
    if (config_optional && access(config_path.c_str(), F_OK) != 0)
        config_path.clear();
    if (!config_path.empty() && !load_sim_config(config_path, cfg, err)) {
        std::fprintf(stderr, "caracara-sim: %s\n", err.c_str());
        return 1;
    }
    if (realistic >= 0)
        cfg.realistic_timing = realistic;
    if (clock_hz) {
        if (clock_hz < 1000 || clock_hz > 3400000) {
            std::fprintf(stderr, "caracara-sim: --clock-hz must be 1000..3400000\n");
            return 2;
        }
        cfg.i2c_clock_hz = static_cast<uint32_t>(clock_hz);
    }

    SimVehicle vehicle(cfg);
    std::unique_ptr<DiveReplay> replay;
    if (!replay_path.empty()) {
        std::vector<uint8_t> bytes;
        std::string why;
        if (!read_whole_file(replay_path, bytes, why)) {
            std::fprintf(stderr, "caracara-sim: cannot replay %s\n", why.c_str());
            return 2;
        }
        dive::Dive d = dive::decode(bytes);
        if (!d.ok()) {
            std::fprintf(stderr, "caracara-sim: cannot replay %s: %s\n", replay_path.c_str(), d.message.c_str());
            return 2;
        }
        replay = std::make_unique<DiveReplay>(vehicle, std::move(d));
        vehicle.add_stepped(replay.get());
    }

    dbus::EventPtr event;
    if (int r = open_event_loop(event, {SIGTERM, SIGINT}); r < 0) {
        std::fprintf(stderr, "caracara-sim: sd_event: %s\n", errno_name(-r).c_str());
        return 1;
    }

    DeviceServer server(event.get(), vehicle);
    if (!kernel_bridge.empty() && !socket_given)
        socket_path = "(none)";
    else if (int r = server.listen(socket_path); r < 0) {
        std::fprintf(stderr, "caracara-sim: cannot listen on %s: %s\n", socket_path.c_str(), errno_name(-r).c_str());
        return 1;
    }

    std::unique_ptr<KernelBridge> bridge;
    if (!kernel_bridge.empty()) {
        bridge = std::make_unique<KernelBridge>(event.get(), vehicle, cfg);
        if (int r = bridge->open(kernel_bridge); r < 0) {
            std::fprintf(stderr, "caracara-sim: cannot serve the kernel bridge %s: %s\n", kernel_bridge.c_str(),
                         errno_name(-r).c_str());
            return 1;
        }
    }

    dbus::BusPtr bus;
    std::unique_ptr<Inspector> inspector;
    if (use_dbus) {
        if (int r = dbus::open_bus(bus_choice, "caracara-sim", bus); r < 0) {
            std::fprintf(stderr, "caracara-sim: cannot connect to %s: %s\n", bus_choice.describe().c_str(),
                         errno_name(-r).c_str());
            return 1;
        }
        inspector = std::make_unique<Inspector>(bus.get(), vehicle, server);
        if (int r = inspector->start(); r < 0) {
            std::fprintf(stderr, "caracara-sim: cannot publish org.caracara.Simulator1: %s\n", errno_name(-r).c_str());
            return 1;
        }
        sd_bus_attach_event(bus.get(), event.get(), SD_EVENT_PRIORITY_NORMAL);
    }

    Physics physics{&vehicle, 0, static_cast<uint64_t>(1000000 / physics_hz)};
    uint64_t now_us = 0;
    sd_event_now(event.get(), CLOCK_MONOTONIC, &now_us);
    sd_event_source* phys = nullptr;
    sd_event_add_time(event.get(), &phys, CLOCK_MONOTONIC, now_us, 1, on_physics, &physics); // 0 = 250 ms slack
    sd_event_source_set_enabled(phys, SD_EVENT_ON);
    dbus::SourcePtr phys_guard(phys);

    std::printf("caracara-sim: %zu thrusters on %s at %u Hz%s; device socket %s%s%s\n", vehicle.thrusters().size(),
                vehicle.i2c_path().c_str(), vehicle.i2c().clock_hz(),
                vehicle.realistic_timing() ? " (realistic timing)" : "", socket_path.c_str(),
                bridge ? "; kernel bridge " : "", kernel_bridge.c_str());
    if (cfg.vehicle.mass_kg)
        std::printf("caracara-sim: thrust in newtons through the vehicle's description: mass %.3g kg%s\n",
                    *cfg.vehicle.mass_kg, cfg.vehicle.inertia_kg_m2 ? ", inertia given" : "");
    std::fflush(stdout);
    sd_notify(0, "READY=1\nSTATUS=Simulating the vehicle");

    int r = sd_event_loop(event.get());
    return r < 0 ? 1 : 0;
}
