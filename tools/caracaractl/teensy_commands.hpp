// caracaractl's Teensy commands (org.caracara.Teensy1): turning, servos, distance sensors and the
// front drive. Each is a Command's run.
#pragma once

#include "tools/caracaractl/command.hpp"

namespace caracara::ctl {

// Turn and TurnTo reply only when the Teensy reports the turn finished (up to 60 s).
CommandRun cmd_turn;
CommandRun cmd_turn_to;
CommandRun cmd_servo;
CommandRun cmd_distance;
CommandRun cmd_wheels;
CommandRun cmd_stop_wheels;

} // namespace caracara::ctl
