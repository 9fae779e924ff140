// caracaractl's held motion commands: thrust, motion and packet, kept alive by re-sending
// (tools/caracaractl/hold.hpp) until ^C, --for or --once. Each is a Command's run.
#pragma once

#include "tools/caracaractl/command.hpp"

#include <string>

namespace caracara::ctl {

CommandRun cmd_thrust;
CommandRun cmd_motion;
// motion's words as it takes them: EnumNames<frames::PilotAxis>, '_' spelled '-' ("turn-right").
std::string motion_words();
// A packet that kills or powers off is sent once, whatever --for says.
CommandRun cmd_packet;

} // namespace caracara::ctl
