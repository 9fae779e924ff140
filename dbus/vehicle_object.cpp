#include "dbus/vehicle_object.hpp"

#include "dbus/announcer.hpp"
#include "dbus/directions_reply.hpp"
#include "dbus/bus_scan_reply.hpp"
#include "dbus/error_reply.hpp"
#include "dbus/preflight_reply.hpp"
#include "dbus/vehicle_names.hpp"

#include <cstring>
#include <memory>
#include <tuple>
#include <vector>

namespace caracara::dbus {

namespace {

using Parts = VehicleObject::Parts;
Vehicle& vehicle(void* userdata) { return static_cast<Parts*>(userdata)->vehicle; }

int read_ints(sd_bus_message* m, std::vector<int32_t>& out) {
    const void* p = nullptr;
    size_t n = 0;
    int r = sd_bus_message_read_array(m, 'i', &p, &n);
    if (r < 0)
        return r;
    out.resize(n / sizeof(int32_t));
    if (n)
        std::memcpy(out.data(), p, n);
    return 0;
}

int m_set_thrust(sd_bus_message* m, void* userdata, sd_bus_error*) {
    // Read in place (the message keeps an int32 array aligned): no copy, no allocation per call.
    const void* p = nullptr;
    size_t n = 0;
    if (int r = sd_bus_message_read_array(m, 'i', &p, &n); r < 0)
        return r;
    return reply(m, vehicle(userdata).motors().set_thrust({static_cast<const int32_t*>(p), n / sizeof(int32_t)}, sender(m)));
}

int m_set_motion(sd_bus_message* m, void* userdata, sd_bus_error*) {
    AxisDemand d{};
    if (int r = sd_bus_message_read(m, "dddddd", &d[0], &d[1], &d[2], &d[3], &d[4], &d[5]); r < 0)
        return r;
    return reply(m, vehicle(userdata).motors().set_motion(d, sender(m)));
}

int m_apply_packet(sd_bus_message* m, void* userdata, sd_bus_error*) {
    std::vector<int32_t> v;
    if (int r = read_ints(m, v); r < 0)
        return r;
    // Replied to when the vehicle says the packet is done (PacketHandler::apply).
    static_cast<Parts*>(userdata)->packets.apply(v, sender(m), reply_later(m));
    return 1;
}

int m_kill(sd_bus_message* m, void* userdata, sd_bus_error*) {
    vehicle(userdata).kill(KillSource::DBus, "Kill() from " + sender(m), reply_later(m));
    return 1;
}

int m_clear_kill(sd_bus_message* m, void* userdata, sd_bus_error*) { return reply(m, vehicle(userdata).clear_kill()); }

int m_clear_kill_override(sd_bus_message* m, void* userdata, sd_bus_error*) {
    const char* condition = nullptr;
    if (int r = sd_bus_message_read(m, "s", &condition); r < 0)
        return r;
    return reply(m, static_cast<Parts*>(userdata)->failsafes.clear_kill_override(condition, sender(m)));
}

std::vector<std::tuple<std::string, std::string, int32_t>> failsafes(const Parts& d) {
    std::vector<std::tuple<std::string, std::string, int32_t>> out;
    for (const ActiveFailsafe& f : d.failsafes.active())
        out.emplace_back(condition_name(f.condition), action_name(f.effective()), f.thruster);
    return out;
}

int m_power_off(sd_bus_message* m, void* userdata, sd_bus_error*) {
    const char* confirmation = nullptr;
    if (int r = sd_bus_message_read(m, "s", &confirmation); r < 0)
        return r;
    vehicle(userdata).power_off(confirmation, reply_later(m));
    return 1;
}

int m_set_leds(sd_bus_message* m, void* userdata, sd_bus_error*) {
    uint8_t red = 0, green = 0, blue = 0;
    if (int r = sd_bus_message_read(m, "yyy", &red, &green, &blue); r < 0)
        return r;
    // Replied to when the Teensy answered; other calls are served meanwhile.
    const Result res = static_cast<Parts*>(userdata)->teensy.set_leds(red, green, blue, reply_later(m));
    return res.ok() ? 1 : reply(m, res);
}

using D = const Parts&;
int m_set_profile(sd_bus_message* m, void* userdata, sd_bus_error*) {
    const char* name = nullptr;
    if (int r = sd_bus_message_read(m, "s", &name); r < 0)
        return r;
    return reply(m, vehicle(userdata).motors().set_profile(name));
}

int m_motor_test(sd_bus_message* m, void* userdata, sd_bus_error*) {
    int32_t thruster = 0, value = 0;
    if (int r = sd_bus_message_read(m, "ii", &thruster, &value); r < 0)
        return r;
    return reply(m, static_cast<Parts*>(userdata)->motor_test.run(thruster, value, sender(m)));
}

int m_detect_directions(sd_bus_message* m, void* userdata, sd_bus_error*) {
    return run_detection(m, static_cast<Parts*>(userdata)->directions, sender(m));
}

int m_preflight(sd_bus_message* m, void* userdata, sd_bus_error*) {
    return run_preflight(m, static_cast<Parts*>(userdata)->preflight);
}

int m_scan_bus(sd_bus_message* m, void* userdata, sd_bus_error*) {
    return scan_bus(m, static_cast<Parts*>(userdata)->bus_scan);
}

const ControlSettings& control(D d) { return d.control; }

constexpr Member kMembers[] = {
    member(SD_BUS_METHOD_WITH_ARGS("SetThrust", SD_BUS_ARGS("ai", values), SD_BUS_NO_RESULT, m_set_thrust, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("SetMotion", SD_BUS_ARGS("d", x, "d", y, "d", z, "d", yaw, "d", pitch, "d", roll),
                                   SD_BUS_NO_RESULT, m_set_motion, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("ApplyPacket", SD_BUS_ARGS("ai", packet), SD_BUS_NO_RESULT, m_apply_packet, kUnpriv)),
    member(SD_BUS_METHOD("Kill", "", "", m_kill, kUnpriv)),
    member(SD_BUS_METHOD("ClearKill", "", "", m_clear_kill, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("ClearKillOverride", SD_BUS_ARGS("s", condition), SD_BUS_NO_RESULT,
                                   m_clear_kill_override, kUnpriv)),
    member(SD_BUS_SIGNAL_WITH_ARGS("Failsafe", SD_BUS_ARGS("s", condition, "s", action, "i", thruster), 0)),
    property<[](D d) { return failsafes(d); }>("Failsafes", kChange, kChangeFailsafes),
    member(SD_BUS_METHOD_WITH_ARGS("PowerOff", SD_BUS_ARGS("s", confirmation), SD_BUS_NO_RESULT, m_power_off, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("MotorTest", SD_BUS_ARGS("i", thruster, "i", value), SD_BUS_NO_RESULT, m_motor_test,
                                   kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("DetectDirections", SD_BUS_NO_ARGS, SD_BUS_RESULT("a(sddddd)", thrusters, "s", fragment),
                                   m_detect_directions, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("Preflight", SD_BUS_NO_ARGS, SD_BUS_RESULT("a(sbss)", items), m_preflight, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("ScanBus", SD_BUS_NO_ARGS, SD_BUS_RESULT("a(qiysyi)", devices, "a(ss)", thrusters),
                                   m_scan_bus, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("SetLeds", SD_BUS_ARGS("y", red, "y", green, "y", blue), SD_BUS_NO_RESULT, m_set_leds,
                                   kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("SetProfile", SD_BUS_ARGS("s", name), SD_BUS_NO_RESULT, m_set_profile, kUnpriv)),
    property<[](D d) { return d.vehicle.readings().state_name(); }>("State", kChange, kChangeState),
    property<[](D d) { return d.vehicle.readings().kill_source_name(); }>("KillSource", kChange, kChangeState),
    property<[](D d) -> const auto& { return d.vehicle.readings().motor_values(); }>("MotorValues", kChange, kChangeMotors),
    property<[](D d) -> const auto& { return d.vehicle.readings().requested_values(); }>("RequestedValues", kChange, kChangeMotors),
    property<[](D d) { return d.vehicle.readings().budget_limit(); }>("BudgetLimit", kChange, kChangeMotors),
    property<[](D d) { return d.vehicle.readings().saturated(); }>("Saturated", kChange, kChangeMotors),
    property<[](D d) { return policy_name(control(d).budget_policy); }>("BudgetPolicy", kConst),
    property<[](D d) -> const auto& { return d.vehicle.readings().profile().name; }>("Profile", kChange, kChangeProfile),
    property<[](D d) { return d.vehicle.readings().profile().factor; }>("ProfileFactor", kChange, kChangeProfile),
    property<[](D d) { auto l = d.teensy.leds(); return std::tuple{l[0], l[1], l[2]}; }>("Leds", kChange, kChangeLeds),
    property<[](D d) { return d.vehicle.readings().command_age_ms(); }>("CommandAgeMs", kChange, kTelemetryTick),
    property<[](D d) -> const auto& { return d.vehicle.readings().controller_client(); }>("Controller", kChange, kChangeController),
    property<[](D d) { return std::tuple{d.motor_test.active_thruster(), d.motor_test.value()}; }>(
        "MotorTest", kChange, kChangeMotors | kChangeController | kChangeState),
    property<[](D d) { return d.motor_test.limit(); }>("MotorTestLimit", kConst),
    property<[](D d) { return control(d).command_timeout_ms; }>("CommandTimeoutMs", kConst),
    property<[](D d) { return control(d).arming_delay_ms; }>("ArmingDelayMs", kConst),
    property<[](D d) { return double(control(d).loop_rate_hz); }>("LoopRateHz", kConst),
    property<[](D d) { return d.loop.cycles(); }>("Cycles", kChange, kCounterTick), // every cycle: 1 Hz
    // Deadlines in CLOCK_MONOTONIC microseconds (sd-bus's and sd-event's time base; the same on
    // every process of the host, so a reader on it turns them into a time left); 0: none.
    property<[](D d) { return d.failsafes.surfacing_until() / 1000; }>("SurfacingUntil", kChange, kChangeState),
    property<[](D d) { return d.failsafes.settings().surface.duration_ms; }>("SurfaceDurationMs", kConst),
    property<[](D d) { return d.failsafes.pilot_lost_kill_at() / 1000; }>("PilotLostKillAt", kChange, kChangeFailsafes),
    property<[](D d) { return d.failsafes.settings().rule(FailsafeCondition::PilotLost).persistence_ms; }>(
        "PilotLostPersistenceMs", kConst),
};
constexpr auto kVtable = vtable(kMembers);

} // namespace

VehicleObject::VehicleObject(sd_bus* bus, const Parts& parts)
    : parts_(parts), object_(bus, kRootPath, kVehicleIface, kMembers, kVtable, &parts_) {}

void VehicleObject::emit_failsafe(const ActiveFailsafe& f) {
    sd_bus_emit_signal(object_.bus(), object_.path().c_str(), object_.iface(), "Failsafe", "ssi",
                       std::string(condition_name(f.condition)).c_str(), std::string(action_name(f.effective())).c_str(),
                       int32_t(f.thruster));
}

} // namespace caracara::dbus
