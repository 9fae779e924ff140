// caracaractl's commissioning commands: motor-test (one thruster alone, held) and
// detect-directions (the daemon's pulse-and-watch run, docs/commissioning.md). Each is a
// Command's run.
#pragma once

#include "tools/caracaractl/command.hpp"

namespace caracara::ctl {

// One thruster, the others at zero, held like thrust: caracarad stops it when the re-sends
// (every 100 ms) stop for its keep-alive (500 ms), and when this client leaves.
CommandRun cmd_motor_test;
// Runs the daemon's direction detection and prints each thruster's finding; --write FILE gets
// the [[thruster]] fragment (never applied by caracarad itself). Exit 0 when every thruster was
// decided, 1 when one is inconclusive.
CommandRun cmd_detect_directions;

} // namespace caracara::ctl
