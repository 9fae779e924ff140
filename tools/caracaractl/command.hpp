// One entry of caracaractl's command table (tools/caracaractl/caracaractl.cpp): its name, usage,
// help line, argument count, the options it takes and the function that runs it.
#pragma once

#include "tools/caracaractl/arguments.hpp"
#include "tools/caracaractl/options.hpp"

#include <cstddef>

namespace caracara::ctl {

// Which command options a command takes.
enum CommandOption : unsigned {
    kOptNone = 0,
    kOptHold = 1 << 0,        // --for SECONDS, --once
    kOptAll = 1 << 1,         // --all
    kOptYesPowerOff = 1 << 2, // --yes-power-off
    kOptValue = 1 << 3,       // --value V
    kOptWrite = 1 << 4,       // --write FILE
};

// What a command runs, given the client, its values (exactly nargs of them) and the command
// options; returns the exit status, throws Failure. The commands are declared with it.
using CommandRun = int(Client&, const Args&, const Options&);

// nargs of a command that takes 1 to 6 WORD=VALUE arguments (motion), checked by the command.
inline constexpr size_t kWordArgs = ~size_t{0};

struct Command {
    const char* name;
    const char* synopsis;
    const char* help;
    size_t nargs;
    CommandRun* run;
    const char* group = nullptr; // starts a new section of --help
    unsigned options = kOptNone;
};

} // namespace caracara::ctl
