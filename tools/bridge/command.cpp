#include "tools/bridge/command.hpp"

#include "core/frames.hpp"
#include "tools/bridge/pilot_seat.hpp"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

namespace caracara::bridge {

using nlohmann::json;

namespace {

constexpr std::size_t kMotors = 8;
constexpr std::size_t kMaxProfileName = 256;

// Each parse fills the command's arguments from its JSON object; "" or why it was refused.
using Parse = std::string (*)(const json& j, std::vector<CommandArg>& args);

std::string no_args(const json&, std::vector<CommandArg>&) { return ""; }

// SetMotion's arguments, in the seed's axes (the D-Bus contract), from a demand core/frames made.
void demand_args(const AxisDemand& d, std::vector<CommandArg>& args) {
    for (const double v : d)
        args.emplace_back(v);
}

// A finite JSON number; a component left out is 0.
std::string component(const json& j, const std::string& key, double& out, const std::string& what) {
    const auto it = j.find(key);
    if (it == j.end())
        return "";
    if (!it->is_number() || !std::isfinite(it->get<double>()))
        return what + " '" + key + "' must be a number";
    out = it->get<double>();
    return "";
}

// One of a Twist's vectors: {"x","y","z"}, nothing else.
std::string twist_vector(const json& j, const char* name, frames::Vec3& v) {
    const auto it = j.find(name);
    if (it == j.end())
        return "";
    if (!it->is_object())
        return std::string("motion's '") + name + "' must be an object {\"x\",\"y\",\"z\"}";
    for (const auto& [key, _] : it->items())
        if (key != "x" && key != "y" && key != "z")
            return std::string("motion's '") + name + "' takes x, y, z, not '" + key + "'";
    const std::string what = std::string("motion ") + name;
    for (auto [key, out] : {std::pair{"x", &v.x}, std::pair{"y", &v.y}, std::pair{"z", &v.z}})
        if (std::string why = component(*it, key, *out, what); !why.empty())
            return why;
    return "";
}

// The flat fields /command/motion took before issue 43, in the seed's axes (x was port): Foxglove's
// users read x as forward, so they are refused by name, never taken as a Twist's.
constexpr std::string_view kSeedFields[] = {"x", "y", "z", "yaw", "pitch", "roll"};

// A geometry_msgs/Twist in REP 103 body FLU (what Foxglove's Teleop panel publishes), each
// component -1..1 of full demand, converted by core/frames.
std::string motion(const json& j, std::vector<CommandArg>& args) {
    for (const auto& [key, _] : j.items()) {
        for (const std::string_view old : kSeedFields)
            if (key == old)
                return "motion is a Twist in body FLU, {\"linear\":{\"x\":forward,\"y\":left,\"z\":up},"
                       "\"angular\":{\"x\":roll right,\"y\":nose down,\"z\":turn left}}: the flat '" + key +
                       "' of the seed's axes is refused (docs/foxglove.md)";
        if (key != "linear" && key != "angular")
            return "motion takes \"linear\" and \"angular\", not '" + key + "'";
    }
    frames::BodyMotion m;
    if (std::string why = twist_vector(j, "linear", m.linear); !why.empty())
        return why;
    if (std::string why = twist_vector(j, "angular", m.angular); !why.empty())
        return why;
    demand_args(frames::from_flu(m), args);
    return "";
}

// The cockpit's motion in a pilot's words (EnumNames<frames::PilotAxis>), converted by core/frames.
std::string drive(const json& j, std::vector<CommandArg>& args) {
    frames::PilotMotion m;
    for (const auto& [key, _] : j.items()) {
        const auto axis = parse_name<frames::PilotAxis>(key);
        if (!axis) {
            std::string names;
            for (const auto& n : EnumNames<frames::PilotAxis>::table)
                names += (names.empty() ? "" : ", ") + std::string(n.name);
            return "drive takes " + names + ", not '" + key + "'";
        }
        if (std::string why = component(j, key, frames::pilot_axis(m, *axis), "drive"); !why.empty())
            return why;
    }
    demand_args(frames::from_pilot(m), args);
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

// The pilot's seat: {"action": "claim" | "take-over" | "release", "name": the client in words}.
std::string seat(const json& j, std::vector<CommandArg>& args) {
    for (const auto& [key, _] : j.items())
        if (key != "action" && key != "name")
            return "seat takes \"action\" and \"name\", not '" + key + "'";
    const auto action = j.find("action");
    if (action == j.end() || !action->is_string() || !parse_name<SeatAction>(action->get_ref<const std::string&>()))
        return "seat needs 'action': \"claim\", \"take-over\" or \"release\"";
    args.emplace_back(action->get<std::string>());
    const auto name = j.find("name");
    if (name == j.end()) {
        args.emplace_back(std::string());
        return "";
    }
    if (!name->is_string() || !PilotSeat::valid_name(name->get_ref<const std::string&>()))
        return "seat's 'name' must be up to " + std::to_string(PilotSeat::kMaxName) + " printable ASCII characters";
    args.emplace_back(name->get<std::string>());
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
    {{CommandKind::Motion, "/command/motion", "SetMotion", CommandReply::None, CommandSeat::Needed, milliseconds(0)}, motion},
    {{CommandKind::Thrust, "/command/thrust", "SetThrust", CommandReply::None, CommandSeat::Needed, milliseconds(0)}, thrust},
    {{CommandKind::Kill, "/command/kill", "Kill", CommandReply::None, CommandSeat::Anyone, milliseconds(0)}, no_args},
    {{CommandKind::ClearKill, "/command/clear_kill", "ClearKill", CommandReply::None, CommandSeat::Needed, milliseconds(0)}, no_args},
    {{CommandKind::Leds, "/command/leds", "SetLeds", CommandReply::None, CommandSeat::Needed, milliseconds(0)}, leds},
    {{CommandKind::Profile, "/command/profile", "SetProfile", CommandReply::None, CommandSeat::Needed, milliseconds(0)}, profile},
    {{CommandKind::MotorTest, "/command/motor_test", "MotorTest", CommandReply::None, CommandSeat::Needed, milliseconds(0)}, motor_test},
    {{CommandKind::DetectDirections, "/command/detect_directions", "DetectDirections", CommandReply::Directions,
      CommandSeat::Needed, kDetectTimeout},
     no_args},
    {{CommandKind::Drive, "/command/drive", "SetMotion", CommandReply::None, CommandSeat::Needed, milliseconds(0)}, drive},
    {{CommandKind::Seat, "/command/seat", nullptr, CommandReply::None, CommandSeat::Anyone, milliseconds(0)}, seat},
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
    return std::size(kCommands) == static_cast<std::size_t>(CommandKind::Seat) + 1;
}());

} // namespace caracara::bridge
