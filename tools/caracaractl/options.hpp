// The command options given after a caracaractl command (--for, --once, --all, --value, --write,
// --yes-power-off), parsed before the command runs.
#pragma once

#include "tools/caracaractl/hold.hpp"

#include <cstdint>
#include <optional>
#include <string>

namespace caracara::ctl {

struct Options {
    bool yes_power_off = false;
    bool all = false;    // monitor --all
    bool for_given = false;
    HoldOptions hold;    // thrust, motion, packet, motor-test: --for SECONDS, --once
    std::optional<int32_t> value; // motor-test --value V
    std::string write_path;       // detect-directions --write FILE
};

} // namespace caracara::ctl
