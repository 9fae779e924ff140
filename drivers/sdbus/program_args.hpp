// The command line as caracara's programs read it (caracarad, caracara-sim, caracara-bridge,
// caracara-ros): "--name VALUE" and "--name=VALUE" alike, -h/--help and --version, and the bus
// options each of them takes (--system, --user, --bus-address ADDR), written once. A bad command
// line ends the program at once with exit status 2, its name and the problem on stderr.
#pragma once

#include "drivers/sdbus/sdbus.hpp"

#include <functional>
#include <string>
#include <string_view>

namespace caracara::dbus {

class ProgramArgs {
public:
    // `help` prints the program's help on stdout.
    ProgramArgs(const char* program, const char* version, int argc, char** argv, std::function<void()> help);

    // Moves to the next argument that is the program's own: help and --version are answered here
    // (exit 0), the bus options go into `bus`. False at the end.
    bool next(BusChoice& bus);
    // The current argument is `name` or `name=VALUE` (an option with a value).
    bool is(std::string_view name) const;
    // The current argument is exactly `name` (an option without one).
    bool flag(std::string_view name) const { return arg_ == name; }
    // Its value: after '=' or the next argument; a usage error when there is none or it is empty.
    std::string value();
    [[noreturn]] void unknown() const;
    [[noreturn]] void usage_error(const std::string& message) const;

private:
    const char* program_;
    const char* version_;
    int argc_;
    char** argv_;
    std::function<void()> help_;
    int at_ = 0;
    std::string arg_;
};

} // namespace caracara::dbus
