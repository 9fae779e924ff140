#include "tools/bridge/command.hpp"

#include <limits>
#include <nlohmann/json.hpp>

namespace caracara::bridge {

using nlohmann::json;

namespace {

constexpr const char* kAxes[] = {"x", "y", "z", "yaw", "pitch", "roll"};
constexpr std::size_t kMotors = 8;
constexpr std::size_t kMaxProfileName = 256;

// Each parse fills the command's arguments from its JSON object; "" or why it was refused.
using Parse = std::string (*)(const json& j, std::vector<CommandArg>& args);

std::string no_args(const json&, std::vector<CommandArg>&) { return ""; }

std::string motion(const json& j, std::vector<CommandArg>& args) {
    for (const char* axis : kAxes) {
        const auto it = j.find(axis);
        if (it != j.end() && !it->is_number())
            return std::string("motion axis '") + axis + "' must be a number";
        args.emplace_back(it == j.end() ? 0.0 : it->get<double>()); // an axis left out is 0
    }
    return "";
}

bool is_int32(const json& v) {
    return v.is_number_integer() && v.get<int64_t>() >= std::numeric_limits<int32_t>::min() &&
           v.get<int64_t>() <= std::numeric_limits<int32_t>::max();
}

std::string thrust(const json& j, std::vector<CommandArg>& args) {
    const auto it = j.find("values");
    if (it == j.end() || !it->is_array() || it->size() != kMotors)
        return "thrust needs 'values': an array of 8 integers";
    std::vector<int32_t> values;
    for (const json& v : *it) {
        if (!v.is_number_integer())
            return "thrust values must be integers";
        if (!is_int32(v))
            return "thrust value out of the int32 range";
        values.push_back(v.get<int32_t>());
    }
    args.emplace_back(std::move(values));
    return "";
}

std::string leds(const json& j, std::vector<CommandArg>& args) {
    for (const char* colour : {"red", "green", "blue"}) {
        const auto it = j.find(colour);
        if (it == j.end() || !it->is_number_integer() || it->get<int64_t>() < 0 || it->get<int64_t>() > 255)
            return std::string("leds needs '") + colour + "': an integer 0..255";
        args.emplace_back(static_cast<uint8_t>(it->get<int64_t>()));
    }
    return "";
}

std::string profile(const json& j, std::vector<CommandArg>& args) {
    const auto it = j.find("name");
    if (it == j.end() || !it->is_string() || it->get_ref<const std::string&>().size() > kMaxProfileName ||
        it->get_ref<const std::string&>().find('\0') != std::string::npos)
        return "profile needs 'name': a string";
    args.emplace_back(it->get<std::string>());
    return "";
}

std::string motor_test(const json& j, std::vector<CommandArg>& args) {
    for (const char* key : {"thruster", "value"}) {
        const auto it = j.find(key);
        if (it == j.end() || !is_int32(*it))
            return std::string("motor_test needs '") + key + "': an integer";
        args.emplace_back(it->get<int32_t>());
    }
    return "";
}

// Detection pulses eight thrusters, each after the vehicle settles (up to its settle timeout).
constexpr std::chrono::milliseconds kDetectTimeout = std::chrono::minutes(10);

struct Row {
    CommandSpec spec;
    Parse parse;
};

using std::chrono::milliseconds;
constexpr Row kCommands[] = {
    {{CommandKind::Motion, "/command/motion", "SetMotion", CommandReply::None, milliseconds(0)}, motion},
    {{CommandKind::Thrust, "/command/thrust", "SetThrust", CommandReply::None, milliseconds(0)}, thrust},
    {{CommandKind::Kill, "/command/kill", "Kill", CommandReply::None, milliseconds(0)}, no_args},
    {{CommandKind::ClearKill, "/command/clear_kill", "ClearKill", CommandReply::None, milliseconds(0)}, no_args},
    {{CommandKind::Leds, "/command/leds", "SetLeds", CommandReply::None, milliseconds(0)}, leds},
    {{CommandKind::Profile, "/command/profile", "SetProfile", CommandReply::None, milliseconds(0)}, profile},
    {{CommandKind::MotorTest, "/command/motor_test", "MotorTest", CommandReply::None, milliseconds(0)}, motor_test},
    {{CommandKind::DetectDirections, "/command/detect_directions", "DetectDirections", CommandReply::Directions,
      kDetectTimeout},
     no_args},
};

const Row& row(CommandKind kind) { return kCommands[static_cast<std::size_t>(kind)]; }

} // namespace

std::optional<CommandKind> command_topic(std::string_view topic) {
    for (const auto& r : kCommands)
        if (topic == r.spec.topic)
            return r.spec.kind;
    return std::nullopt;
}

const CommandSpec& command_spec(CommandKind kind) { return row(kind).spec; }

CommandParse parse_command(CommandKind kind, std::string_view text) {
    const json j = json::parse(text.begin(), text.end(), nullptr, false);
    if (j.is_discarded())
        return {std::nullopt, "not JSON"};
    if (!j.is_object())
        return {std::nullopt, "a command is a JSON object"};
    Command c{kind, {}};
    if (std::string why = row(kind).parse(j, c.args); !why.empty())
        return {std::nullopt, std::move(why)};
    return {std::move(c), {}};
}

// The table is indexed by the enum: each row in the enum's order.
static_assert([] {
    for (std::size_t i = 0; i < std::size(kCommands); ++i)
        if (static_cast<std::size_t>(kCommands[i].spec.kind) != i)
            return false;
    return std::size(kCommands) == static_cast<std::size_t>(CommandKind::DetectDirections) + 1;
}());

} // namespace caracara::bridge
