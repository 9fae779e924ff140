#include "tools/bridge/command.hpp"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

namespace caracara::bridge {

using nlohmann::json;

namespace {

constexpr struct { CommandKind kind; const char* topic; } kTopics[] = {
    {CommandKind::Motion, "/command/motion"}, {CommandKind::Thrust, "/command/thrust"},
    {CommandKind::Kill, "/command/kill"},     {CommandKind::ClearKill, "/command/clear_kill"},
    {CommandKind::Leds, "/command/leds"},     {CommandKind::Profile, "/command/profile"},
};

constexpr const char* kAxes[] = {"x", "y", "z", "yaw", "pitch", "roll"};
constexpr std::size_t kMotors = 8;
constexpr std::size_t kMaxProfileName = 256;

CommandParse refuse(std::string why) { return {std::nullopt, std::move(why)}; }

} // namespace

std::optional<CommandKind> command_topic(std::string_view topic) {
    for (const auto& t : kTopics)
        if (topic == t.topic)
            return t.kind;
    return std::nullopt;
}

std::string_view command_topic_name(CommandKind kind) {
    for (const auto& t : kTopics)
        if (t.kind == kind)
            return t.topic;
    return "";
}

CommandParse parse_command(CommandKind kind, std::string_view text) {
    const json j = json::parse(text.begin(), text.end(), nullptr, false);
    if (j.is_discarded())
        return refuse("not JSON");
    if (!j.is_object())
        return refuse("a command is a JSON object");
    Command c;
    c.kind = kind;
    switch (kind) {
    case CommandKind::Motion:
        for (std::size_t i = 0; i < 6; ++i) {
            const auto it = j.find(kAxes[i]);
            if (it == j.end())
                continue; // an axis left out is 0
            if (!it->is_number())
                return refuse(std::string("motion axis '") + kAxes[i] + "' must be a number");
            c.axes[i] = it->get<double>();
        }
        break;
    case CommandKind::Thrust: {
        const auto it = j.find("values");
        if (it == j.end() || !it->is_array() || it->size() != kMotors)
            return refuse("thrust needs 'values': an array of 8 integers");
        for (const json& v : *it) {
            if (!v.is_number_integer())
                return refuse("thrust values must be integers");
            const auto n = v.get<int64_t>();
            if (n < std::numeric_limits<int32_t>::min() || n > std::numeric_limits<int32_t>::max())
                return refuse("thrust value out of the int32 range");
            c.thrust.push_back(static_cast<int32_t>(n));
        }
        break;
    }
    case CommandKind::Kill:
    case CommandKind::ClearKill:
        break;
    case CommandKind::Leds: {
        const char* names[] = {"red", "green", "blue"};
        for (std::size_t i = 0; i < 3; ++i) {
            const auto it = j.find(names[i]);
            if (it == j.end() || !it->is_number_integer() || it->get<int64_t>() < 0 || it->get<int64_t>() > 255)
                return refuse(std::string("leds needs '") + names[i] + "': an integer 0..255");
            c.rgb[i] = static_cast<uint8_t>(it->get<int64_t>());
        }
        break;
    }
    case CommandKind::Profile: {
        const auto it = j.find("name");
        if (it == j.end() || !it->is_string() || it->get_ref<const std::string&>().size() > kMaxProfileName ||
            it->get_ref<const std::string&>().find('\0') != std::string::npos)
            return refuse("profile needs 'name': a string");
        c.profile = it->get<std::string>();
        break;
    }
    }
    return {std::move(c), {}};
}

} // namespace caracara::bridge
