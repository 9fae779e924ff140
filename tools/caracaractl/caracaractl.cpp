// caracaractl: query and command caracarad (org.caracara.Vehicle1) from the shell, in the style
// of timedatectl. Arguments are parsed completely before anything is sent; value ranges are the
// daemon's business (it answers with named errors), only the D-Bus wire types are checked here.
// Here: the command table, --help and the options; the commands live by subject in
// tools/caracaractl/*_commands.cpp, their values' parsing in tools/caracaractl/arguments.cpp.
#include "tools/caracaractl/bridge_forward.hpp"
#include "tools/caracaractl/check.hpp"
#include "tools/caracaractl/command.hpp"
#include "tools/caracaractl/commissioning_commands.hpp"
#include "tools/caracaractl/dives.hpp"
#include "tools/caracaractl/render.hpp"
#include "tools/caracaractl/teensy_commands.hpp"
#include "tools/caracaractl/thrust_commands.hpp"
#include "tools/caracaractl/vehicle_commands.hpp"
#include "tools/caracaractl/scan.hpp"
#include "tools/client/client.hpp"
#include "tools/client/ssh_target.hpp"

#include <iostream>
#include <string>
#include <string_view>

using namespace caracara::client;
using namespace caracara::ctl;

namespace {

CommandRun cmd_help;

constexpr Command kCommands[] = {
    {"status", "", "Show vehicle, thrusters, Teensy and I2C bus (default)", 0, cmd_status, "Vehicle commands"},
    {"monitor", "[--all]", "Print property changes, timestamped, until ^C", 0, cmd_monitor, nullptr, kOptAll},
    {"thrust", "V0 V1 V2 V3 V4 V5 V6 V7", "Hold the eight motor values (-8850..8850) until ^C", 8, cmd_thrust,
     nullptr, kOptHold},
    {"motion", "WORD=VALUE...", "Hold a motion in a pilot's words (forward=, starboard=, up=, turn-right=, nose-up=,\n"
     "                                   roll-right=; each -1..1, negative the opposite) until ^C", kWordArgs, cmd_motion,
     nullptr, kOptHold},
    {"packet", "W0 ... W12", "Hold a 13-word Caracara packet (motors, kill, power-off, RGB)", 13, cmd_packet,
     nullptr, kOptHold},
    {"kill", "", "Zero every thruster at once and latch the kill", 0, cmd_kill},
    {"motor-test", "N --value V", "Run thruster N alone at V (bounded, armed only) until ^C or --for", 1,
     cmd_motor_test, nullptr, kOptHold | kOptValue},
    {"scan", "", "Probe every thruster address on every mux channel (killed only); compare with the configuration", 0,
     [](Client& c, const Args&, const Options&) { return scan_bus(c); }},
    {"detect-directions", "[--write FILE]",
     "Pulse each thruster, still and armed, and tell ok/reversed/inconclusive from the rotation", 0,
     cmd_detect_directions, nullptr, kOptWrite},
    {"check", "", "Preflight: one go/no-go table before a dive, each no-go with what to do; exit 0 when all go", 0,
     [](Client& c, const Args&, const Options&) { return run_check(c); }},
    {"clear-kill", "", "Clear the kill, e.g. the one every start comes up with (arming, then ready)", 0,
     cmd_clear_kill},
    {"clear-kill-override", "CONDITION",
     "Clear a failsafe's kill while its condition (e.g. water-detect) still holds, deliberately", 1,
     cmd_clear_kill_override},
    {"profile", "NAME", "Select a thrust profile (a scale factor, e.g. water, air)", 1, cmd_profile},
    {"leds", "R G B", "Set the LED colour (0..255 each)", 3, cmd_leds},
    {"power-off", "[--yes-power-off]", "Power the vehicle off, irreversibly (asks to confirm)", 0, cmd_power_off,
     nullptr, kOptYesPowerOff},
    {"turn", "RAD", "Turn by RAD radians; returns when done", 1, cmd_turn, "Teensy commands"},
    {"turn-to", "RAD", "Turn to heading RAD radians; returns when done", 1, cmd_turn_to},
    {"servo", "ID DEG", "Set servo ID to DEG degrees", 2, cmd_servo},
    {"distance", "ID", "Read distance sensor ID (prints millimeters)", 1, cmd_distance},
    {"wheels", "LEFT RIGHT", "Set the front drive speeds (-128..127)", 2, cmd_wheels},
    {"stop-wheels", "DUTY", "Stop the drive with brake duty DUTY (0..255)", 1, cmd_stop_wheels},
    {"help", "", "Show this help", 0, cmd_help},
};

const Command* find_command(std::string_view name) {
    for (const Command& c : kCommands)
        if (name == c.name)
            return &c;
    return nullptr;
}

std::string synopsis(const Command& c) { return std::string(c.name) + (*c.synopsis ? " " : "") + c.synopsis; }

void print_help() {
    std::cout << "caracaractl [OPTIONS...] COMMAND [ARGS...]\n\n"
                 "Query and command the Caracara vehicle daemon (caracarad, org.caracara.Vehicle1).\n";
    for (const Command& c : kCommands) {
        if (c.group)
            std::cout << '\n' << c.group << ":\n";
        std::cout << strf("  %-32s %s\n", synopsis(c).c_str(), c.help);
    }
    std::cout << dive_help();
    std::cout << bridge_forward_help();
    std::cout << "\nOptions (before the command):\n"
                 "  --system                         Connect to the system bus (default)\n"
                 "  --user                           Connect to the user's session bus\n"
                 "  --bus-address ADDR               Connect to the bus at ADDR (e.g. unix:path=/tmp/bus)\n"
                 "  -H --host=[USER@]HOST[:PORT]     Connect to the system bus of HOST over SSH (ssh runs\n"
                 "                                   systemd-stdio-bridge there, as for systemctl -H)\n"
                 "  --yes-power-off                  Confirm power-off without asking (also after it)\n"
                 "  --version                        Show the version\n"
                 "  -h --help                        Show this help\n"
                 "\nCommand options (after the command, before or after its values):\n"
                 "  --for SECONDS                    thrust, motion, packet, motor-test: hold for SECONDS (decimals\n"
                 "                                   allowed, e.g. 2.5), then let go\n"
                 "  --once                           thrust, motion, packet: send once and exit; caracarad\n"
                 "                                   zeroes the thrusters as soon as caracaractl has left\n"
                 "  --value V                        motor-test: the motor value (-8850..8850; caracarad\n"
                 "                                   refuses beyond commissioning.motor_test_limit)\n"
                 "  --write FILE                     detect-directions: write the [[thruster]] tables with\n"
                 "                                   the reversal flags found to FILE\n"
                 "  --all                            monitor: print every announcement, with the fast\n"
                 "                                   counters (Cycles, CommandAgeMs, OrdersSent,\n"
                 "                                   StatusReads, Frames, BusyRetries, Transactions) and\n"
                 "                                   values announced again unchanged, hidden by default\n"
                 "\nHolding: caracarad zeroes the thrusters when the client that sent the last thrust,\n"
                 "motion or packet leaves the bus, or when no command arrives within its\n"
                 "CommandTimeoutMs (500 ms by default). So thrust, motion and packet stay connected and\n"
                 "re-send their command every 100 ms (at most a third of CommandTimeoutMs) until Ctrl-C,\n"
                 "SIGTERM or the end of --for. They then exit without sending a zero themselves: the\n"
                 "daemon zeroes the thrusters when this client leaves. If it was the last pilot (no\n"
                 "other client that commanded since the vehicle was armed is connected), the\n"
                 "pilot-lost failsafe kills the vehicle after its persistence (5 s by default);\n"
                 "clear-kill arms it again. A re-send the daemon refuses\n"
                 "(e.g. Killed after a kill) is printed and ends caracaractl at once with status 1.\n"
                 "A packet that kills or powers off is sent once.\n"
                 "\nCommands wait for the daemon's answer (turn and turn-to up to 60 s, others 25 s).\n"
                 "Changing the vehicle needs root or membership in the caracara group; reading does not.\n"
                 "\nExit status:\n"
                 "  0  success\n"
                 "  1  the daemon refused the request (its D-Bus error is printed), or a dive file\n"
                 "     cannot be read\n"
                 "  2  usage error, or power-off not confirmed; nothing was sent\n"
                 "  3  caracarad is not running, did not answer, or the bus cannot be reached (with\n"
                 "     -H also: the host cannot be reached over SSH, or the link dropped)\n"
                 "  4  permission denied (with -H also: SSH refused the login)\n"
                 "\nWith -H the commanding client is the SSH link: when it drops, caracarad zeroes the\n"
                 "thrusters; a link that stalls is caught by the command timeout (docs/topside.md).\n";
}

int cmd_help(Client&, const Args&, const Options&) {
    print_help();
    return kExitOk;
}

} // namespace

int main(int argc, char** argv) {
    caracara::dbus::BusChoice choice;
    Options options;
    const Command* command = nullptr;
    try {
        int i = 1;
        for (; i < argc; ++i) {
            const std::string a = argv[i];
            if (a == "--system") {
                choice = {caracara::dbus::BusChoice::Kind::System, {}};
            } else if (a == "--user") {
                choice = {caracara::dbus::BusChoice::Kind::User, {}};
            } else if (a == "--bus-address" || a.starts_with("--bus-address=")) {
                std::string address;
                if (a.size() > 13)
                    address = a.substr(14);
                else if (i + 1 < argc)
                    address = argv[++i];
                if (address.empty())
                    usage_error("--bus-address needs an address");
                choice = {caracara::dbus::BusChoice::Kind::Address, address};
            } else if (a == "-H" || a == "--host" || a.starts_with("-H") || a.starts_with("--host=")) {
                // As systemctl and busctl spell it: -H HOST, -HHOST, --host HOST, --host=HOST.
                std::string host;
                if (a == "-H" || a == "--host")
                    host = i + 1 < argc ? argv[++i] : "";
                else
                    host = a.starts_with("--host=") ? a.substr(7) : a.substr(2);
                if (!parse_ssh_target(host))
                    usage_error("-H needs [USER@]HOST[:PORT] (PORT a number 1..65535), not '" + host + "'");
                choice = {caracara::dbus::BusChoice::Kind::Remote, host};
            } else if (a == "--yes-power-off") {
                options.yes_power_off = true;
            } else if (a == "-h" || a == "--help") {
                print_help();
                return kExitOk;
            } else if (a == "--version") {
                std::cout << "caracaractl " << CARACARA_VERSION << '\n';
                return kExitOk;
            } else if (a.starts_with("-")) {
                usage_error("unknown option '" + a + "'");
            } else {
                break;
            }
        }
        const std::string name = i < argc ? argv[i++] : "status";
        if (is_dive_command(name))
            return run_dive_command(name, Args(argv + i, argv + argc));
        if (name == "bridge")
            return run_bridge_forward(choice, Args(argv + i, argv + argc));
        command = find_command(name);
        if (!command)
            usage_error("unknown command '" + name + "'");
        Args args;
        auto takes = [&](unsigned option, const std::string& a) {
            if (!(command->options & option))
                usage_error("option '" + a + "' does not apply to " + command->name);
        };
        for (; i < argc; ++i) {
            const std::string a = argv[i];
            if (a == "-h" || a == "--help") {
                print_help();
                return kExitOk;
            }
            if (a == "--yes-power-off") {
                takes(kOptYesPowerOff, a);
                options.yes_power_off = true;
            } else if (a == "--all") {
                takes(kOptAll, a);
                options.all = true;
            } else if (a == "--once") {
                takes(kOptHold, a);
                options.hold.once = true;
            } else if (a == "--for" || a.starts_with("--for=")) {
                takes(kOptHold, "--for");
                if (a == "--for" && i + 1 >= argc)
                    usage_error("--for needs a number of seconds");
                options.hold.duration_usec = parse_duration(a == "--for" ? argv[++i] : a.substr(6));
                options.for_given = true;
            } else if (a == "--value" || a.starts_with("--value=")) {
                takes(kOptValue, "--value");
                if (a == "--value" && i + 1 >= argc)
                    usage_error("--value needs a motor value");
                options.value = parse_int(a == "--value" ? argv[++i] : a.substr(8), "--value");
            } else if (a == "--write" || a.starts_with("--write=")) {
                takes(kOptWrite, "--write");
                if (a == "--write" && i + 1 >= argc)
                    usage_error("--write needs a file name");
                options.write_path = a == "--write" ? argv[++i] : a.substr(8);
            } else if (a.starts_with("--")) {
                usage_error("unknown option '" + a + "'"); // values never start with "--"
            } else {
                args.push_back(a);
            }
        }
        if (options.hold.once && options.for_given)
            usage_error("--for and --once exclude each other");
        if (command->nargs == kWordArgs ? args.empty() || args.size() > 6 : args.size() != command->nargs)
            usage_error(command->nargs == kWordArgs
                            ? strf("%s takes 1 to 6 WORD=VALUE arguments (%s), got %zu", command->name,
                                   motion_words().c_str(), args.size())
                            : strf("%s takes %zu argument%s, got %zu", command->name, command->nargs,
                                   command->nargs == 1 ? "" : "s", args.size()));
        Client client(choice);
        return command->run(client, args, options);
    } catch (const Failure& f) {
        std::cerr << "caracaractl: " << f.message << '\n';
        if (f.code == kExitUsage) {
            if (command)
                std::cerr << "Usage: caracaractl " << synopsis(*command)
                          << (command->options & kOptHold ? " [--for SECONDS | --once]" : "") << '\n';
            std::cerr << "Try 'caracaractl --help' for more information.\n";
        }
        return f.code;
    }
}
