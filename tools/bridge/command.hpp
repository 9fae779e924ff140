// A pilot's command published by a Foxglove client (clientPublish) on one of the command
// topics (docs/foxglove.md), decoded from its JSON into the D-Bus call's arguments. Only the
// JSON's shape and the D-Bus wire types are checked here; ranges are the daemon's business (it
// answers with named errors). Each command is one row of one table (command.cpp): its topic,
// its argument parse, its D-Bus method and what its reply carries.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace caracara::bridge {

// Motion: a Twist in REP 103 body FLU (Foxglove); Drive: a pilot's words (the cockpit). Both are
// SetMotion, converted by core/frames (docs/frames.md). Seat: the bridge's own pilot's seat
// (tools/bridge/pilot_seat.hpp), no D-Bus call.
enum class CommandKind : uint8_t { Motion, Thrust, Kill, ClearKill, Leds, Profile, MotorTest, DetectDirections, Drive, Seat };

// Who may send a command: only the client in the pilot's seat (taking it when free), or anyone
// (a kill, and asking for the seat).
enum class CommandSeat : uint8_t { Needed, Anyone };

// What a successful reply carries back to the client that sent the command.
enum class CommandReply : uint8_t {
    None,       // nothing: only a refusal is told
    Directions, // DetectDirections' a(sddddd)s, as JSON (docs/foxglove.md)
};

// One D-Bus argument (a Seat command's: its action's name, then the client's name or ""): int32 'i', byte 'y', double 'd', string 's', int32 array 'ai'.
using CommandArg = std::variant<int32_t, uint8_t, double, std::string, std::vector<int32_t>>;

struct Command {
    CommandKind kind = CommandKind::Kill;
    std::vector<CommandArg> args; // the D-Bus method's arguments, in its order
};

struct CommandParse {
    std::optional<Command> command;
    std::string error;                // why it was refused, when command is empty
};

struct CommandSpec {
    CommandKind kind;
    std::string_view topic;           // "/command/motion"
    const char* member;               // the org.caracara.Vehicle1 method; null: the bridge's own (Seat)
    CommandReply reply;
    CommandSeat seat;
    std::chrono::milliseconds timeout; // the reply's; 0: sd-bus's default (25 s)
};

// "/command/motion" -> Motion, ...; nullopt for a topic that is no command.
std::optional<CommandKind> command_topic(std::string_view topic);
const CommandSpec& command_spec(CommandKind kind);
inline std::string_view command_topic_name(CommandKind kind) { return command_spec(kind).topic; }

// Decodes the JSON payload of a message on a command topic.
CommandParse parse_command(CommandKind kind, std::string_view json);

} // namespace caracara::bridge
