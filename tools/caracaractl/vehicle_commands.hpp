// caracaractl's commands on the vehicle's state: status, monitor, kill and its clearing, the
// thrust profile, the LEDs and power-off. Each is a Command's run (tools/caracaractl/command.hpp).
#pragma once

#include "tools/caracaractl/command.hpp"

namespace caracara::ctl {

CommandRun cmd_status;
CommandRun cmd_monitor;
CommandRun cmd_kill;
CommandRun cmd_clear_kill;
CommandRun cmd_clear_kill_override;
CommandRun cmd_profile;
CommandRun cmd_leds;
// Asks to type "power-off" on a terminal unless --yes-power-off.
CommandRun cmd_power_off;

} // namespace caracara::ctl
