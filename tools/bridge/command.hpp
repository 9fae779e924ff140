// A pilot's command published by a Foxglove client (clientPublish) on one of the command
// topics (docs/foxglove.md), decoded from its JSON. Only the JSON's shape and the D-Bus wire
// types are checked here; ranges are the daemon's business (it answers with named errors).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace caracara::bridge {

enum class CommandKind : uint8_t { Motion, Thrust, Kill, ClearKill, Leds, Profile };

// "/command/motion" -> Motion, ...; nullopt for a topic that is no command.
std::optional<CommandKind> command_topic(std::string_view topic);
std::string_view command_topic_name(CommandKind kind);

struct Command {
    CommandKind kind = CommandKind::Kill;
    std::array<double, 6> axes{};     // Motion: x, y, z, yaw, pitch, roll
    std::vector<int32_t> thrust;      // Thrust: the eight motor values
    std::array<uint8_t, 3> rgb{};     // Leds
    std::string profile;              // Profile
};

struct CommandParse {
    std::optional<Command> command;
    std::string error;                // why it was refused, when command is empty
};

// Decodes the JSON payload of a message on a command topic.
CommandParse parse_command(CommandKind kind, std::string_view json);

} // namespace caracara::bridge
