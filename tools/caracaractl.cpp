// caracaractl: query and command caracarad (org.caracara.Vehicle1) from the shell, in the style
// of timedatectl. Arguments are parsed completely before anything is sent; value ranges are the
// daemon's business (it answers with named errors), only the D-Bus wire types are checked here.
#include "client.hpp"
#include "monitor.hpp"
#include "render.hpp"

#include <charconv>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <string>
#include <string_view>
#include <unistd.h>
#include <vector>

using namespace caracaractl;

namespace {

using Args = std::vector<std::string>;

struct Options {
    bool yes_power_off = false;
};

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

// --- commands ----------------------------------------------------------------------------------

int cmd_status(Client& c, const Args&, const Options&) {
    print_status(std::cout, c.get_objects());
    return kExitOk;
}

int cmd_monitor(Client& c, const Args&, const Options&) { return run_monitor(c); }

int cmd_thrust(Client& c, const Args& a, const Options&) {
    c.call(kRootPath, kVehicleIface, "SetThrust", int_array(parse_ints(a, "motor value")));
    return kExitOk;
}

int cmd_motion(Client& c, const Args& a, const Options&) {
    const char* names[] = {"X", "Y", "Z", "YAW", "PITCH", "ROLL"};
    double v[6];
    for (size_t i = 0; i < 6; ++i)
        v[i] = parse_double(a[i], names[i]);
    c.call(kRootPath, kVehicleIface, "SetMotion", append_args("dddddd", v[0], v[1], v[2], v[3], v[4], v[5]));
    return kExitOk;
}

int cmd_packet(Client& c, const Args& a, const Options&) {
    c.call(kRootPath, kVehicleIface, "ApplyPacket", int_array(parse_ints(a, "packet word")));
    return kExitOk;
}

int cmd_kill(Client& c, const Args&, const Options&) {
    c.call(kRootPath, kVehicleIface, "Kill");
    return kExitOk;
}

int cmd_clear_kill(Client& c, const Args&, const Options&) {
    c.call(kRootPath, kVehicleIface, "ClearKill");
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

struct Command {
    const char* name;
    const char* synopsis;
    const char* help;
    size_t nargs;
    int (*run)(Client&, const Args&, const Options&);
    const char* group = nullptr; // starts a new section of --help
};

constexpr Command kCommands[] = {
    {"status", "", "Show vehicle, thrusters, Teensy and I2C bus (default)", 0, cmd_status, "Vehicle commands"},
    {"monitor", "", "Print every property change, timestamped, until ^C", 0, cmd_monitor},
    {"thrust", "V0 V1 V2 V3 V4 V5 V6 V7", "Set the eight motor values (-8850..8850)", 8, cmd_thrust},
    {"motion", "X Y Z YAW PITCH ROLL", "Set a 6-axis motion demand (each -1..1)", 6, cmd_motion},
    {"packet", "W0 ... W12", "Apply a 13-word Caracara packet (motors, kill, power-off, RGB)", 13, cmd_packet},
    {"kill", "", "Zero every thruster at once and latch the kill", 0, cmd_kill},
    {"clear-kill", "", "Clear the kill (arming, then ready)", 0, cmd_clear_kill},
    {"leds", "R G B", "Set the LED colour (0..255 each)", 3, cmd_leds},
    {"power-off", "[--yes-power-off]", "Power the vehicle off, irreversibly (asks to confirm)", 0, cmd_power_off},
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
    std::cout << "\nOptions (before the command):\n"
                 "  --system                         Connect to the system bus (default)\n"
                 "  --user                           Connect to the user's session bus\n"
                 "  --bus-address ADDR               Connect to the bus at ADDR (e.g. unix:path=/tmp/bus)\n"
                 "  --yes-power-off                  Confirm power-off without asking (also after it)\n"
                 "  -h --help                        Show this help\n"
                 "\nCommands wait for the daemon's answer (turn and turn-to up to 60 s, others 25 s).\n"
                 "Changing the vehicle needs root or membership in the caracara group; reading does not.\n"
                 "\nExit status:\n"
                 "  0  success\n"
                 "  1  the daemon refused the request (its D-Bus error is printed)\n"
                 "  2  usage error, or power-off not confirmed; nothing was sent\n"
                 "  3  caracarad is not running, did not answer, or the bus cannot be reached\n"
                 "  4  permission denied\n";
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
            } else if (a == "--yes-power-off") {
                options.yes_power_off = true;
            } else if (a == "-h" || a == "--help") {
                print_help();
                return kExitOk;
            } else if (a.starts_with("-")) {
                usage_error("unknown option '" + a + "'");
            } else {
                break;
            }
        }
        const std::string name = i < argc ? argv[i++] : "status";
        command = find_command(name);
        if (!command)
            usage_error("unknown command '" + name + "'");
        Args args;
        for (; i < argc; ++i) {
            const std::string a = argv[i];
            if (a == "-h" || a == "--help") {
                print_help();
                return kExitOk;
            }
            if (a == "--yes-power-off" && command->run == cmd_power_off)
                options.yes_power_off = true;
            else
                args.push_back(a);
        }
        if (args.size() != command->nargs)
            usage_error(strf("%s takes %zu argument%s, got %zu", command->name, command->nargs,
                             command->nargs == 1 ? "" : "s", args.size()));
        Client client(choice);
        return command->run(client, args, options);
    } catch (const Failure& f) {
        std::cerr << "caracaractl: " << f.message << '\n';
        if (f.code == kExitUsage) {
            if (command)
                std::cerr << "Usage: caracaractl " << synopsis(*command) << '\n';
            std::cerr << "Try 'caracaractl --help' for more information.\n";
        }
        return f.code;
    }
}
