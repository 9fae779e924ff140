#include "tools/foxglove/channels.hpp"

#include "core/frames.hpp"
#include "drivers/protocol/seabotix.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

namespace caracara::foxglove {

using nlohmann::json;

namespace {

json integer() { return {{"type", "integer"}}; }
json number() { return {{"type", "number"}}; }
json boolean() { return {{"type", "boolean"}}; }
json string() { return {{"type", "string"}}; }
json array_of(json items) { return {{"type", "array"}, {"items", std::move(items)}}; }
json fixed_array(json items, std::size_t n) {
    return {{"type", "array"}, {"items", std::move(items)}, {"minItems", n}, {"maxItems", n}};
}

// An object schema whose every property is required and no other is allowed: a message that
// validates has exactly the documented fields.
json object(const char* title, json properties) {
    json required = json::array();
    for (const auto& [key, _] : properties.items())
        required.push_back(key);
    return {{"$schema", "https://json-schema.org/draft/2020-12/schema"}, {"title", title}, {"type", "object"},
            {"properties", std::move(properties)}, {"required", std::move(required)}, {"additionalProperties", false}};
}

json time_schema() {
    return {{"type", "object"},
            {"properties", {{"sec", integer()}, {"nsec", integer()}}},
            {"required", {"sec", "nsec"}}};
}

json vector3() {
    return {{"type", "object"},
            {"properties", {{"x", number()}, {"y", number()}, {"z", number()}}},
            {"required", {"x", "y", "z"}}};
}

std::vector<ChannelInfo> make_channels() {
    std::vector<ChannelInfo> out;
    out.push_back({ChannelKind::VehicleState, 0, "/vehicle/state", "caracara.VehicleState",
                   object("caracara.VehicleState",
                          {{"state", {{"enum", {"arming", "ready", "killed", "powered-off", "fault"}}}},
                           {"kill_source", string()},
                           {"profile", string()},
                           {"profile_factor", number()},
                           {"budget_limit", integer()},
                           {"saturated", boolean()},
                           {"command_age_ms", integer()},
                           {"controller", string()},
                           {"controller_name", string()},
                           {"leds", fixed_array(integer(), 3)},
                           {"failsafes", array_of({{"type", "object"},
                                                   {"properties", {{"condition", string()},
                                                                   {"action", {{"enum", {"warn", "exclude", "surface", "kill"}}}},
                                                                   {"thruster", integer()}}},
                                                   {"required", {"condition", "action", "thruster"}},
                                                   {"additionalProperties", false}})},
                           {"excluded", array_of(integer())},
                           {"surfacing_ms", integer()},
                           {"ascent_left_ms", integer()},
                           {"pilot_lost_left_ms", integer()},
                           {"pilot_lost_ms", integer()},
                           {"motor_test",
                            {{"type", "object"},
                             {"properties", {{"thruster", integer()}, {"value", integer()}}},
                             {"required", {"thruster", "value"}}}},
                           {"motor_test_limit", integer()}})
                       .dump()});
    out.push_back({ChannelKind::Motors, 0, "/vehicle/motors", "caracara.Motors",
                   object("caracara.Motors", {{"applied", fixed_array(integer(), kThrusters)},
                                              {"requested", fixed_array(integer(), kThrusters)}})
                       .dump()});
    for (unsigned i = 0; i < kThrusters; ++i)
        out.push_back({ChannelKind::Thruster, i, "/thruster/" + std::to_string(i), "caracara.Thruster",
                       object("caracara.Thruster", {{"index", integer()},
                                                    {"reachable", boolean()},
                                                    {"speed", integer()},
                                                    {"ordered_value", integer()},
                                                    {"current", number()},
                                                    {"temperature", number()},
                                                    {"fault_bits", integer()},
                                                    {"faults", array_of(string())}})
                           .dump()});
    out.push_back({ChannelKind::Teensy, 0, "/teensy", "caracara.Teensy",
                   object("caracara.Teensy",
                          {{"online", boolean()},
                           {"orientation",
                            {{"type", "object"},
                             {"properties", {{"yaw", number()}, {"pitch", number()}, {"roll", number()}}},
                             {"required", {"yaw", "pitch", "roll"}}}},
                           {"distances", array_of(integer())},
                           {"servos", array_of(integer())},
                           {"task", string()},
                           {"link",
                            {{"type", "object"},
                             {"properties", {{"frames", integer()}, {"busy_retries", integer()}, {"link_errors", integer()}}},
                             {"required", {"frames", "busy_retries", "link_errors"}}}}})
                       .dump()});
    out.push_back({ChannelKind::I2cBus, 0, "/i2c", "caracara.I2cBus",
                   object("caracara.I2cBus", {{"state", string()},
                                              {"transactions", integer()},
                                              {"errors", integer()},
                                              {"recoveries", integer()},
                                              {"recovery_failures", integer()},
                                              {"last_error", string()}})
                       .dump()});
    // foxglove.Log and foxglove.FrameTransform as Foxglove's own JSON schemas define them.
    out.push_back({ChannelKind::Events, 0, "/events", "foxglove.Log",
                   object("foxglove.Log", {{"timestamp", time_schema()},
                                           {"level", {{"type", "integer"}, {"minimum", 0}, {"maximum", 5}}},
                                           {"message", string()},
                                           {"name", string()},
                                           {"file", string()},
                                           {"line", {{"type", "integer"}, {"minimum", 0}}}})
                       .dump()});
    out.push_back({ChannelKind::Attitude, 0, "/tf", "foxglove.FrameTransform",
                   object("foxglove.FrameTransform",
                          {{"timestamp", time_schema()},
                           {"parent_frame_id", string()},
                           {"child_frame_id", string()},
                           {"translation", vector3()},
                           {"rotation",
                            {{"type", "object"},
                             {"properties", {{"x", number()}, {"y", number()}, {"z", number()}, {"w", number()}}},
                             {"required", {"x", "y", "z", "w"}}}}})
                       .dump()});
    return out;
}

json time_json(uint64_t ns) { return {{"sec", ns / 1'000'000'000u}, {"nsec", ns % 1'000'000'000u}}; }

// JSON has no NaN or infinity: a value the vehicle cannot measure is sent as 0.
double finite(double v) { return std::isfinite(v) ? v : 0.0; }

} // namespace

const std::vector<ChannelInfo>& channels() {
    static const std::vector<ChannelInfo> all = make_channels();
    return all;
}

std::size_t channel_position(ChannelKind kind, unsigned index) {
    const auto& all = channels();
    for (std::size_t i = 0; i < all.size(); ++i)
        if (all[i].kind == kind && (kind != ChannelKind::Thruster || all[i].index == index))
            return i;
    return 0;
}

std::string to_json(const VehicleState& m) {
    json failsafes = json::array();
    std::vector<int64_t> excluded;
    for (const ActiveFailsafe& f : m.failsafes) {
        failsafes.push_back({{"condition", f.condition}, {"action", f.action}, {"thruster", f.thruster}});
        if (f.action == "exclude" && f.thruster >= 0)
            excluded.push_back(f.thruster);
    }
    return json{{"state", m.state},
                {"kill_source", m.kill_source},
                {"profile", m.profile},
                {"profile_factor", finite(m.profile_factor)},
                {"budget_limit", m.budget_limit},
                {"saturated", m.saturated},
                {"command_age_ms", m.command_age_ms},
                {"controller", m.controller},
                {"controller_name", m.controller_name},
                {"leds", m.leds},
                {"failsafes", failsafes},
                {"excluded", excluded},
                {"surfacing_ms", m.surfacing_ms},
                {"ascent_left_ms", m.ascent_left_ms},
                {"pilot_lost_left_ms", m.pilot_lost_left_ms},
                {"pilot_lost_ms", m.pilot_lost_ms},
                {"motor_test", {{"thruster", m.motor_test_thruster}, {"value", m.motor_test_value}}},
                {"motor_test_limit", m.motor_test_limit}}
        .dump();
}

std::string to_json(const Motors& m) { return json{{"applied", m.applied}, {"requested", m.requested}}.dump(); }

std::string to_json(const Thruster& m) {
    return json{{"index", m.index},
                {"reachable", m.reachable},
                {"speed", m.speed},
                {"ordered_value", m.ordered_value},
                {"current", finite(m.current)},
                {"temperature", finite(m.temperature)},
                {"fault_bits", m.fault_bits},
                {"faults", m.faults}}
        .dump();
}

std::string to_json(const Teensy& m) {
    return json{{"online", m.online},
                {"orientation", {{"yaw", finite(m.yaw)}, {"pitch", finite(m.pitch)}, {"roll", finite(m.roll)}}},
                {"distances", m.distances},
                {"servos", m.servos},
                {"task", m.task},
                {"link", {{"frames", m.frames}, {"busy_retries", m.busy_retries}, {"link_errors", m.link_errors}}}}
        .dump();
}

std::string to_json(const I2cBus& m) {
    return json{{"state", m.state},
                {"transactions", m.transactions},
                {"errors", m.errors},
                {"recoveries", m.recoveries},
                {"recovery_failures", m.recovery_failures},
                {"last_error", m.last_error}}
        .dump();
}

std::string to_json(const LogEvent& m) {
    return json{{"timestamp", time_json(m.time_ns)},
                {"level", static_cast<int>(m.level)},
                {"message", m.message},
                {"name", m.name},
                {"file", ""},
                {"line", 0}}
        .dump();
}

std::string attitude_json(uint64_t time_ns, double yaw, double pitch, double roll) {
    // REP 103 / 145, as caracara-ros: the FLU body in the ENU world, the heading reference north
    // (+y); core/frames owns the conversion (docs/frames.md).
    const frames::Quaternion q = frames::orientation({finite(yaw), finite(pitch), finite(roll)}, frames::WorldFrame::EnuFlu);
    return json{{"timestamp", time_json(time_ns)},
                {"parent_frame_id", "world"},
                {"child_frame_id", "caracara"},
                {"translation", {{"x", 0.0}, {"y", 0.0}, {"z", 0.0}}},
                {"rotation", {{"x", q.x}, {"y", q.y}, {"z", q.z}, {"w", q.w}}}}
        .dump();
}

std::vector<std::string> fault_names(unsigned bits) {
    std::vector<std::string> out;
    for (const auto f : caracara::kAllFaults)
        if ((bits >> static_cast<unsigned>(f)) & 1u)
            out.emplace_back(caracara::fault_name(f));
    return out;
}

} // namespace caracara::foxglove
