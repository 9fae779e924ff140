#include "tools/bridge/channel_message_builder.hpp"

#include "drivers/protocol/seabotix.hpp"
#include "tools/bridge/failsafe_state.hpp"
#include "tools/foxglove/channels.hpp"

namespace caracara::bridge {

using namespace caracara::client; // the mirrored properties: Props, Value, property()
namespace fg = caracara::foxglove;
using fg::ChannelKind;
using caracara::dbus::kRootPath;

namespace {

std::vector<int64_t> integers(const Value& v) {
    std::vector<int64_t> out;
    for (const Value& item : v.items)
        out.push_back(item.integer());
    return out;
}

} // namespace

void ChannelMessageBuilder::follow_surfacing(const Props& root, uint64_t now) {
    const std::string& state = property(root, "State").s;
    bool surfacing = false;
    if (state != "killed" && state != "powered-off")
        for (const fg::ActiveFailsafe& f : failsafes(root))
            surfacing = surfacing || f.action == "surface";
    if (!surfacing)
        surfacing_since_ = 0;
    else if (!surfacing_since_)
        surfacing_since_ = now;
}

std::optional<std::string> ChannelMessageBuilder::build(std::size_t channel, uint64_t now) const {
    const fg::ChannelInfo& info = fg::channels()[channel];
    switch (info.kind) {
    case ChannelKind::VehicleState:
        return vehicle_state(now);
    case ChannelKind::Motors:
        return motors();
    case ChannelKind::Thruster:
        return thruster(info.index);
    case ChannelKind::Teensy:
    case ChannelKind::Attitude:
        return teensy(info.kind == ChannelKind::Attitude, now);
    case ChannelKind::I2cBus:
        return i2c_bus();
    case ChannelKind::Events:
        break;
    }
    return std::nullopt;
}

std::string ChannelMessageBuilder::vehicle_state(uint64_t now) const {
    const Props& p = mirror_.props(kRootPath, caracara::dbus::kVehicleIface);
    const std::string& controller = property(p, "Controller").s;
    fg::VehicleState s{property(p, "State").s, property(p, "KillSource").s, property(p, "Profile").s,
                       property(p, "ProfileFactor").number(), property(p, "BudgetLimit").integer(),
                       property(p, "Saturated").boolean(), property(p, "CommandAgeMs").integer(), controller,
                       controller == controller_.unique_name ? controller_.words : "", {}, failsafes(p),
                       surfacing_since_ ? static_cast<int64_t>((now - surfacing_since_) / 1'000'000u) : -1};
    const Value& leds = property(p, "Leds");
    for (std::size_t i = 0; i < 3 && i < leds.items.size(); ++i)
        s.leds[i] = leds.items[i].integer();
    add_time_left(p, s);
    if (const Value& test = property(p, "MotorTest"); test.items.size() == 2) {
        s.motor_test_thruster = test.items[0].integer();
        s.motor_test_value = test.items[1].integer();
    }
    s.motor_test_limit = property(p, "MotorTestLimit").integer();
    return fg::to_json(s);
}

std::string ChannelMessageBuilder::motors() const {
    const Props& p = mirror_.props(kRootPath, caracara::dbus::kVehicleIface);
    fg::Motors m;
    const auto applied = integers(property(p, "MotorValues")), requested = integers(property(p, "RequestedValues"));
    for (std::size_t i = 0; i < fg::kThrusters; ++i) {
        m.applied[i] = i < applied.size() ? applied[i] : 0;
        m.requested[i] = i < requested.size() ? requested[i] : 0;
    }
    return fg::to_json(m);
}

std::string ChannelMessageBuilder::thruster(unsigned index) const {
    const Props& p = mirror_.props(std::string(kRootPath) + "/thruster/" + std::to_string(index),
                                  caracara::dbus::kThrusterIface);
    fg::Thruster t;
    t.index = index;
    t.reachable = property(p, "Online").boolean();
    const auto speed = caracara::speed_to_motor(static_cast<uint8_t>(property(p, "ActualSpeed").unsigned_integer()));
    t.speed = speed ? *speed : 0;
    t.ordered_value = property(p, "OrderedValue").integer();
    t.current = property(p, "Current").number();
    t.temperature = property(p, "Temperature").number();
    for (const Value& f : property(p, "Faults").items) {
        t.faults.push_back(f.s);
        for (const auto fault : caracara::kAllFaults)
            if (caracara::fault_name(fault) == f.s)
                t.fault_bits |= 1u << static_cast<unsigned>(fault);
    }
    return fg::to_json(t);
}

// The Teensy's channel, or only its orientation as a foxglove.PoseInFrame (the attitude channel).
std::string ChannelMessageBuilder::teensy(bool attitude_only, uint64_t now) const {
    const Props& p = mirror_.props(caracara::dbus::kTeensyPath, caracara::dbus::kTeensyIface);
    fg::Teensy t;
    const Value& o = property(p, "Orientation");
    if (o.items.size() == 3) {
        t.yaw = o.items[0].number();
        t.pitch = o.items[1].number();
        t.roll = o.items[2].number();
    }
    if (attitude_only)
        return fg::attitude_json(now, t.yaw, t.pitch, t.roll);
    t.online = property(p, "Online").boolean();
    t.distances = integers(property(p, "Distances"));
    t.servos = integers(property(p, "Servos"));
    t.task = property(p, "Task").s;
    t.frames = property(p, "Frames").unsigned_integer();
    t.busy_retries = property(p, "BusyRetries").unsigned_integer();
    t.link_errors = property(p, "LinkErrors").unsigned_integer();
    return fg::to_json(t);
}

std::string ChannelMessageBuilder::i2c_bus() const {
    const Props& p = mirror_.props(caracara::dbus::kBusPath, caracara::dbus::kBusIface);
    fg::I2cBus b{property(p, "State").s,
                 property(p, "Transactions").unsigned_integer(),
                 property(p, "Errors").unsigned_integer(),
                 property(p, "Recoveries").unsigned_integer(),
                 property(p, "RecoveryFailures").unsigned_integer(),
                 property(p, "LastError").s};
    return fg::to_json(b);
}

} // namespace caracara::bridge
