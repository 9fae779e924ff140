// caracarad: the Caracara vehicle daemon. One sd-event loop; see docs/architecture.md.
#include "core/config.hpp"
#include "daemon/loop/log.hpp"
#include "daemon/loop/thread_schedule.hpp"
#include "daemon/vehicle_daemon.hpp"
#include "dbus/bus_input_probe.hpp"
#include "dbus/vehicle_service.hpp"
#include "drivers/devices/emergency_stop.hpp"
#include "drivers/devices/final_stop.hpp"
#include "drivers/platform/hardware.hpp"
#include "drivers/platform/io_error.hpp"
#include "drivers/sdbus/program_args.hpp"
#include "drivers/sdbus/sdbus.hpp"

#include <csignal>
#include <cstdio>
#include <cstring>
#include <string>
#include <systemd/sd-daemon.h>
#include <sysexits.h>
#include <unistd.h>

using namespace caracara;

namespace {

constexpr const char* kDefaultConfig = "/etc/caracara/caracarad.toml";

void usage(FILE* f) {
    std::fputs("Usage: caracarad [OPTIONS]\n"
               "The Caracara vehicle daemon: thrusters, Teensy, kill and power-off on D-Bus.\n\n"
               "  --config FILE          configuration (default /etc/caracara/caracarad.toml;\n"
               "                         built-in defaults when the default file is absent)\n"
               "  --hardware=linux       real devices (default)\n"
               "  --hardware=sim:SOCKET  a running caracara-sim\n"
               "  --system               serve on the system bus (default)\n"
               "  --user                 serve on the user bus\n"
               "  --bus-address ADDR     serve on the bus at ADDR\n"
               "  --check-config         validate the configuration and exit\n"
               "  --zero-thrusters       assert the kill output, order zero to every thruster, stop\n"
               "                         the Teensy's wheels, and exit (systemd's ExecStopPost=)\n"
               "  --version              the version, and exit\n"
               "  -h, --help             this text\n",
               f);
}

// After every end of the daemon (systemd's ExecStopPost=): whatever state the process left
// the hardware in, the thrusters end at zero. Exit 0 when every thruster took its zero.
int zero_thrusters(const DaemonConfig& config, Hardware& hw) {
    const FinalStop::Report r = FinalStop(config, *hw.io, *hw.gpio).run();
    for (const auto& p : r.problems)
        log_error("zeroing: %s", p.c_str());
    log_notice("zeroing after stop: %u of %zu thrusters zeroed%s", r.zeroed, config.thrusters.size(),
               r.kill_output_asserted ? ", kill output asserted" : "");
    return r.ok() ? 0 : 1;
}

int on_signal(sd_event_source* s, const signalfd_siginfo* si, void*) {
    log_notice("received %s: thrusters to zero, exiting", strsignal(static_cast<int>(si->ssi_signo)));
    return sd_event_exit(sd_event_source_get_event(s), 0);
}

} // namespace

int main(int argc, char** argv) {
    std::string config_path;
    std::string hardware = "linux";
    dbus::BusChoice bus_choice;
    bool check_only = false;
    bool zero_only = false;

    dbus::ProgramArgs args("caracarad", CARACARA_VERSION, argc, argv, [] { usage(stdout); });
    while (args.next(bus_choice)) {
        if (args.is("--config")) config_path = args.value();
        else if (args.is("--hardware")) hardware = args.value();
        else if (args.flag("--check-config")) check_only = true;
        else if (args.flag("--zero-thrusters")) zero_only = true;
        else args.unknown();
    }

    // An explicitly named file must exist; the default path may be absent (built-in defaults).
    // The file read, "" for the built-in defaults (the preflight runs the checker on it again).
    std::string config_file = config_path.empty() ? kDefaultConfig : config_path;
    if (config_path.empty() && access(kDefaultConfig, F_OK) != 0)
        config_file.clear();
    const ConfigResult cr =
        config_file.empty() ? parse_config_string("", "built-in defaults") : parse_config_file(config_file);
    if (!cr.ok()) {
        log_error("invalid configuration %s:", config_path.empty() ? kDefaultConfig : config_path.c_str());
        for (const auto& e : cr.errors)
            log_error("  %s", e.c_str());
        sd_notifyf(0, "STATUS=Invalid configuration: %s", cr.errors.empty() ? "?" : cr.errors.front().c_str());
        // EX_CONFIG: caracarad.service has RestartPreventExitStatus=78, so systemd does not
        // restart a daemon that cannot start until someone fixes the file.
        return EX_CONFIG;
    }
    if (check_only) {
        std::printf("configuration OK\n");
        return 0;
    }

    std::string err;
    Hardware hw;
    if (!make_hardware(hardware, hw, err)) {
        log_error("%s", err.c_str());
        return 1;
    }
    if (zero_only)
        return zero_thrusters(*cr.config, hw);

    dbus::EventPtr event;
    if (int r = open_event_loop(event, {SIGTERM, SIGINT, SIGHUP}, on_signal); r < 0) {
        log_error("sd_event_default: %s", errno_name(-r).c_str());
        return 1;
    }
    // A closed log pipe (caracarad | head) is an EPIPE, not the end of the daemon; systemd's
    // IgnoreSIGPIPE= does the same for the service. Terminal stop signals (Ctrl-Z, a background
    // daemon writing to its terminal) would freeze it with the thrusters running.
    for (int sig : {SIGPIPE, SIGTSTP, SIGTTIN, SIGTTOU})
        signal(sig, SIG_IGN);

    // Locked before the daemon's threads are made, so that their stacks are locked too.
    if (cr.config->realtime.lock_memory) {
        if (std::string e = ThreadSchedule::lock_memory(); !e.empty())
            log_warning("realtime: memory not locked: %s", e.c_str());
        else
            log_info("realtime: memory locked");
    }

    // Made before the daemon so that it outlives it: the daemon's lines tell it their kill output.
    EmergencyStop estop;
    VehicleDaemon daemon(event.get(), *hw.io, hw.bus_io(), hw.spi_io(), *hw.gpio, *cr.config);
    daemon.preflight().set_config_file(config_file);
    if (std::string e = daemon.start(); !e.empty()) {
        log_error("%s", e.c_str());
        sd_notifyf(0, "STATUS=%s", e.c_str());
        return 1;
    }

    // If the daemon itself crashes, zero the thrusters from the signal handler instead of
    // leaving them at speed until systemd has restarted us.
    {
        Hardware panic_hw;
        std::string perr;
        if (!make_hardware(hardware, panic_hw, perr))
            log_warning("emergency stop not armed: %s", perr.c_str());
        else if (std::string e = estop.arm(std::move(panic_hw.io), cr.config->i2c.device, cr.config->thrusters, cr.config->spi); !e.empty())
            log_warning("emergency stop not armed: %s", e.c_str());
        else {
            daemon.attach_emergency_stop(estop);
            EmergencyStop::install_fatal_handlers(&estop);
        }
    }

    dbus::BusPtr bus;
    if (int r = dbus::open_bus(bus_choice, "caracarad", bus); r < 0) {
        log_error("cannot connect to %s: %s", bus_choice.describe().c_str(), errno_name(-r).c_str());
        return 1; // the VehicleDaemon destructor has zeroed the thrusters
    }
    // Each D-Bus object gets the parts it shows and drives, not the whole daemon.
    dbus::VehicleService service(bus.get(), {{daemon.vehicle(), daemon.packets(), daemon.teensy(), daemon.loop(),
                                              daemon.config().control, daemon.failsafes(), daemon.motor_test(),
                                              daemon.directions(), daemon.preflight(), daemon.bus_scan()},
                                             daemon.bus(), daemon.bus().monitor(), daemon.teensy(), daemon.events()});
    daemon.events().attach(&service);
    if (int r = service.start(); r < 0) {
        log_error("cannot publish %s on %s: %s", dbus::kBusName, bus_choice.describe().c_str(), errno_name(-r).c_str());
        return 1;
    }
    // Losing the bus ends the loop; the thrusters are zeroed on the way out and systemd restarts us.
    sd_bus_set_exit_on_disconnect(bus.get(), 1);
    sd_bus_attach_event(bus.get(), event.get(), SD_EVENT_PRIORITY_NORMAL);
    dbus::BusInputProbe input_probe(bus.get());
    daemon.loop().set_input_probe(&input_probe);

    daemon.status().start_watchdog();

    log_notice("serving %s on %s with %zu thrusters on %s (%s)", dbus::kBusName, bus_choice.describe().c_str(),
               daemon.bus().size(), cr.config->i2c.device.c_str(), hardware.c_str());
    daemon.status().ready(dbus::kBusName);

    int r = sd_event_loop(event.get());
    if (r > 0) // only sd-bus's exit on disconnect leaves the loop with a failure status
        log_error("lost its connection to the bus: thrusters to zero, exiting");
    daemon.events().attach(nullptr);
    daemon.shutdown();
    EmergencyStop::install_fatal_handlers(nullptr);
    daemon.status().stopping();
    if (r < 0) {
        log_error("event loop failed: %s", errno_name(-r).c_str());
        return 1;
    }
    return r;
}
