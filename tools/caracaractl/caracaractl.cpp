// caracaractl: query and command caracarad (org.caracara.Vehicle1) from the shell, in the style
// of timedatectl. Arguments are parsed completely before anything is sent; value ranges are the
// daemon's business (it answers with named errors), only the D-Bus wire types are checked here.
#include "tools/caracaractl/bridge_forward.hpp"
#include "tools/caracaractl/dives.hpp"
#include "tools/caracaractl/hold.hpp"
#include "tools/caracaractl/monitor.hpp"
#include "tools/caracaractl/render.hpp"
#include "tools/caracaractl/scan.hpp"
#include "tools/client/client.hpp"
#include "tools/client/ssh_target.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <unistd.h>
#include <vector>

using namespace caracara::client;
using namespace caracara::ctl;

namespace {

using Args = std::vector<std::string>;

struct Options {
    bool yes_power_off = false;
    bool all = false;    // monitor --all
    bool for_given = false;
    HoldOptions hold;    // thrust, motion, packet, motor-test: --for SECONDS, --once
    std::optional<int32_t> value; // motor-test --value V
    std::string write_path;       // detect-directions --write FILE
};

// The longest --for: beyond any dive, and far from overflowing the microsecond clock.
constexpr double kMaxHoldSeconds = 1e9;

// Turn and TurnTo reply only when the Teensy reports the turn finished.
constexpr uint64_t kTurnTimeoutUsec = 60'000'000;

[[noreturn]] void usage_error(const std::string& message) { throw Failure{kExitUsage, message}; }

// --- strict argument parsing -----------------------------------------------------------------

template <typename T>
T parse_number(const std::string& text, const std::string& what) {
    const char* begin = text.data();
    const char* end = begin + text.size();
    if (text.size() > 1 && text[0] == '+' && text[1] != '-')
        ++begin; // from_chars takes no '+'
    T value{};
    const auto [stop, ec] = std::from_chars(begin, end, value);
    if (text.empty() || ec == std::errc::invalid_argument || stop != end)
        usage_error(what + " must be a number, not '" + text + "'");
    if (ec == std::errc::result_out_of_range)
        usage_error(what + " '" + text + "' is out of range");
    return value;
}

int32_t parse_int(const std::string& text, const std::string& what) { return parse_number<int32_t>(text, what); }
double parse_double(const std::string& text, const std::string& what) { return parse_number<double>(text, what); }
// D-Bus type 'y': the wire cannot carry anything outside 0..255.
uint8_t parse_byte(const std::string& text, const std::string& what) {
    const int32_t v = parse_number<int32_t>(text, what);
    if (v < 0 || v > 255)
        usage_error(what + " must be 0..255, not '" + text + "'");
    return static_cast<uint8_t>(v);
}

std::vector<int32_t> parse_ints(const Args& args, const char* what) {
    std::vector<int32_t> out;
    for (size_t i = 0; i < args.size(); ++i)
        out.push_back(parse_int(args[i], std::string(what) + " " + std::to_string(i)));
    return out;
}

Client::Appender int_array(std::vector<int32_t> values) {
    return [values = std::move(values)](sd_bus_message* m) {
        return sd_bus_message_append_array(m, 'i', values.data(), values.size() * sizeof(int32_t));
    };
}

// "[1000,0,-500]" for the holding line.
std::string int_list(const std::vector<int32_t>& values) {
    std::string out = "[";
    for (size_t i = 0; i < values.size(); ++i)
        out += (i ? "," : "") + std::to_string(values[i]);
    return out + "]";
}

// --for SECONDS: positive, finite, decimals allowed.
uint64_t parse_duration(const std::string& text) {
    const double seconds = parse_double(text, "--for");
    if (!std::isfinite(seconds) || seconds <= 0 || seconds > kMaxHoldSeconds)
        usage_error("--for needs a positive number of seconds, not '" + text + "'");
    return std::max<uint64_t>(1, static_cast<uint64_t>(std::llround(seconds * 1e6)));
}

// --- commands ----------------------------------------------------------------------------------

int cmd_status(Client& c, const Args&, const Options&) {
    print_status(std::cout, c.get_objects());
    return kExitOk;
}

int cmd_monitor(Client& c, const Args&, const Options& o) { return run_monitor(c, o.all); }

int cmd_thrust(Client& c, const Args& a, const Options& o) {
    const std::vector<int32_t> values = parse_ints(a, "motor value");
    return hold_command(c, "SetThrust", int_array(values), "SetThrust(" + int_list(values) + ")", o.hold);
}

int cmd_motion(Client& c, const Args& a, const Options& o) {
    const char* names[] = {"X", "Y", "Z", "YAW", "PITCH", "ROLL"};
    double v[6];
    for (size_t i = 0; i < 6; ++i)
        v[i] = parse_double(a[i], names[i]);
    return hold_command(c, "SetMotion", append_args("dddddd", v[0], v[1], v[2], v[3], v[4], v[5]),
                        strf("SetMotion(%g, %g, %g, %g, %g, %g)", v[0], v[1], v[2], v[3], v[4], v[5]), o.hold);
}

// One thruster, the others at zero, held like thrust: caracarad stops it when the re-sends
// (every 100 ms) stop for its keep-alive (500 ms), and when this client leaves.
int cmd_motor_test(Client& c, const Args& a, const Options& o) {
    const int32_t thruster = parse_int(a[0], "thruster");
    if (!o.value)
        usage_error("motor-test needs --value V");
    return hold_command(c, "MotorTest", append_args("ii", thruster, *o.value),
                        strf("MotorTest(%d, %d)", thruster, *o.value), o.hold);
}

// Detection pulses eight thrusters, each after the vehicle settles (up to its settle timeout).
constexpr uint64_t kDetectTimeoutUsec = 600'000'000;

// Runs the daemon's direction detection and prints each thruster's finding; --write FILE gets
// the [[thruster]] fragment (never applied by caracarad itself). Exit 0 when every thruster was
// decided, 1 when one is inconclusive.
int cmd_detect_directions(Client& c, const Args&, const Options& o) {
    caracara::dbus::MessagePtr reply = c.call(kRootPath, kVehicleIface, "DetectDirections", {}, kDetectTimeoutUsec);
    const Value rows = read_value(reply.get());
    const Value fragment = read_value(reply.get());
    std::cout << strf("%-8s %-13s %10s %10s %10s %10s %7s\n", "thruster", "verdict", "yaw", "pitch", "roll", "along",
                      "margin");
    bool all_decided = true;
    for (size_t i = 0; i < rows.items.size(); ++i) {
        const auto& f = rows.items[i].items;
        if (f.size() != 6)
            throw Failure{kExitUnavailable, "DetectDirections answered a malformed row"};
        all_decided = all_decided && f[0].s != "inconclusive";
        std::cout << strf("%-8zu %-13s %+10.4f %+10.4f %+10.4f %+10.4f %7.1f\n", i, f[0].s.c_str(), f[1].number(),
                          f[2].number(), f[3].number(), f[4].number(), f[5].number());
    }
    std::cout << "(rad: the attitude change over each pulse; margin: the change along the mixing's rotation\n"
                 " over commissioning.detect_threshold_mrad)\n";
    if (!o.write_path.empty()) {
        FILE* f = std::fopen(o.write_path.c_str(), "w");
        if (!f || std::fputs(fragment.s.c_str(), f) < 0 || std::fclose(f) != 0)
            throw Failure{kExitUnavailable, "cannot write " + o.write_path};
        std::cout << "wrote the [[thruster]] fragment to " << o.write_path << "\n";
    }
    return all_decided ? kExitOk : kExitRefused;
}

// Packet words 8 and 9: killState and powerOffState.
constexpr size_t kPacketKillWord = 8, kPacketPowerOffWord = 9;

int cmd_packet(Client& c, const Args& a, const Options& o) {
    const std::vector<int32_t> words = parse_ints(a, "packet word");
    HoldOptions hold = o.hold;
    // A kill latches and a power-off is final: there is nothing to keep alive, and a repeated
    // power-off would only be refused.
    if (words[kPacketKillWord] != 0 || words[kPacketPowerOffWord] != 0)
        hold = HoldOptions{true, 0};
    return hold_command(c, "ApplyPacket", int_array(words), "ApplyPacket(" + int_list(words) + ")", hold);
}

int cmd_kill(Client& c, const Args&, const Options&) {
    c.call(kRootPath, kVehicleIface, "Kill");
    return kExitOk;
}

int cmd_clear_kill(Client& c, const Args&, const Options&) {
    c.call(kRootPath, kVehicleIface, "ClearKill");
    return kExitOk;
}

int cmd_clear_kill_override(Client& c, const Args& a, const Options&) {
    c.call(kRootPath, kVehicleIface, "ClearKillOverride", append_args("s", a[0].c_str()));
    return kExitOk;
}

int cmd_profile(Client& c, const Args& a, const Options&) {
    c.call(kRootPath, kVehicleIface, "SetProfile", append_args("s", a[0].c_str()));
    return kExitOk;
}

int cmd_leds(Client& c, const Args& a, const Options&) {
    const uint8_t r = parse_byte(a[0], "R"), g = parse_byte(a[1], "G"), b = parse_byte(a[2], "B");
    c.call(kRootPath, kVehicleIface, "SetLeds", append_args("yyy", r, g, b));
    return kExitOk;
}

int cmd_power_off(Client& c, const Args&, const Options& o) {
    if (!o.yes_power_off) {
        if (!isatty(STDIN_FILENO))
            usage_error("power-off is irreversible; confirm with --yes-power-off (stdin is not a terminal)");
        std::cerr << "Powering off the vehicle is irreversible.\nType power-off to confirm: " << std::flush;
        std::string answer;
        if (!std::getline(std::cin, answer) || answer != "power-off")
            usage_error("power-off not confirmed; nothing was sent");
    }
    c.call(kRootPath, kVehicleIface, "PowerOff", append_args("s", "power-off"));
    return kExitOk;
}

int cmd_turn(Client& c, const Args& a, const Options&) {
    c.call(kTeensyPath, kTeensyIface, "Turn", append_args("d", parse_double(a[0], "RAD")), kTurnTimeoutUsec);
    return kExitOk;
}

int cmd_turn_to(Client& c, const Args& a, const Options&) {
    c.call(kTeensyPath, kTeensyIface, "TurnTo", append_args("d", parse_double(a[0], "RAD")), kTurnTimeoutUsec);
    return kExitOk;
}

int cmd_servo(Client& c, const Args& a, const Options&) {
    const uint8_t id = parse_byte(a[0], "ID"), degrees = parse_byte(a[1], "DEG");
    c.call(kTeensyPath, kTeensyIface, "SetServo", append_args("yy", id, degrees));
    return kExitOk;
}

int cmd_distance(Client& c, const Args& a, const Options&) {
    auto reply = c.call(kTeensyPath, kTeensyIface, "GetDistance", append_args("y", parse_byte(a[0], "ID")));
    uint16_t mm = 0;
    if (int r = sd_bus_message_read(reply.get(), "q", &mm); r < 0)
        throw Failure{kExitRefused, "malformed GetDistance reply from caracarad"};
    std::cout << mm << " mm\n";
    return kExitOk;
}

int cmd_wheels(Client& c, const Args& a, const Options&) {
    const int32_t left = parse_int(a[0], "LEFT"), right = parse_int(a[1], "RIGHT");
    c.call(kTeensyPath, kTeensyIface, "SetSpeed", append_args("ii", left, right));
    return kExitOk;
}

int cmd_stop_wheels(Client& c, const Args& a, const Options&) {
    c.call(kTeensyPath, kTeensyIface, "Stop", append_args("y", parse_byte(a[0], "DUTY")));
    return kExitOk;
}

int cmd_help(Client&, const Args&, const Options&);

// Which command options a command takes.
enum CommandOption : unsigned {
    kOptNone = 0,
    kOptHold = 1 << 0,        // --for SECONDS, --once
    kOptAll = 1 << 1,         // --all
    kOptYesPowerOff = 1 << 2, // --yes-power-off
    kOptValue = 1 << 3,       // --value V
    kOptWrite = 1 << 4,       // --write FILE
};

struct Command {
    const char* name;
    const char* synopsis;
    const char* help;
    size_t nargs;
    int (*run)(Client&, const Args&, const Options&);
    const char* group = nullptr; // starts a new section of --help
    unsigned options = kOptNone;
};

constexpr Command kCommands[] = {
    {"status", "", "Show vehicle, thrusters, Teensy and I2C bus (default)", 0, cmd_status, "Vehicle commands"},
    {"monitor", "[--all]", "Print property changes, timestamped, until ^C", 0, cmd_monitor, nullptr, kOptAll},
    {"thrust", "V0 V1 V2 V3 V4 V5 V6 V7", "Hold the eight motor values (-8850..8850) until ^C", 8, cmd_thrust,
     nullptr, kOptHold},
    {"motion", "X Y Z YAW PITCH ROLL", "Hold a 6-axis motion demand (each -1..1) until ^C", 6, cmd_motion, nullptr,
     kOptHold},
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
        if (args.size() != command->nargs)
            usage_error(strf("%s takes %zu argument%s, got %zu", command->name, command->nargs,
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
