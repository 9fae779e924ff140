#include "dbus/teensy_object.hpp"

#include "dbus/announcer.hpp"
#include "dbus/error_reply.hpp"
#include "dbus/vehicle_names.hpp"

#include <memory>
#include <tuple>

namespace caracara::dbus {

namespace {

TeensyPort& ctl(void* userdata) { return *static_cast<TeensyPort*>(userdata); }

int m_set_speed(sd_bus_message* m, void* userdata, sd_bus_error*) {
    int32_t left = 0, right = 0;
    if (int r = sd_bus_message_read(m, "ii", &left, &right); r < 0)
        return r;
    return reply(m, ctl(userdata).set_speed(left, right, sender(m)));
}

int m_stop(sd_bus_message* m, void* userdata, sd_bus_error*) {
    uint8_t duty = 0;
    if (int r = sd_bus_message_read(m, "y", &duty); r < 0)
        return r;
    return reply(m, ctl(userdata).stop(duty));
}

int m_servo(sd_bus_message* m, void* userdata, sd_bus_error*) {
    uint8_t id = 0, degrees = 0;
    if (int r = sd_bus_message_read(m, "yy", &id, &degrees); r < 0)
        return r;
    return reply(m, ctl(userdata).servo(id, degrees));
}

int m_distance(sd_bus_message* m, void* userdata, sd_bus_error*) {
    uint8_t sensor = 0;
    if (int r = sd_bus_message_read(m, "y", &sensor); r < 0)
        return r;
    uint16_t mm = 0;
    if (Result res = ctl(userdata).distance(sensor, mm); !res.ok())
        return reply(m, res);
    return sd_bus_reply_method_return(m, "q", mm);
}

int turn(sd_bus_message* m, void* userdata, bool absolute) {
    double radians = 0;
    if (int r = sd_bus_message_read(m, "d", &radians); r < 0)
        return r;
    // Replied to when the Teensy confirms; other calls are served meanwhile.
    Result res = ctl(userdata).turn(radians, absolute, sender(m), reply_later(m));
    return res.ok() ? 1 : reply(m, res);
}

int m_turn(sd_bus_message* m, void* userdata, sd_bus_error*) { return turn(m, userdata, false); }
int m_turn_to(sd_bus_message* m, void* userdata, sd_bus_error*) { return turn(m, userdata, true); }

using C = const TeensyPort&;
constexpr uint32_t kTick = kTelemetryTick;

constexpr Member kMembers[] = {
    member(SD_BUS_METHOD_WITH_ARGS("SetSpeed", SD_BUS_ARGS("i", left, "i", right), SD_BUS_NO_RESULT, m_set_speed, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("Turn", SD_BUS_ARGS("d", radians), SD_BUS_NO_RESULT, m_turn, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("TurnTo", SD_BUS_ARGS("d", heading), SD_BUS_NO_RESULT, m_turn_to, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("Stop", SD_BUS_ARGS("y", brake_duty), SD_BUS_NO_RESULT, m_stop, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("SetServo", SD_BUS_ARGS("y", id, "y", degrees), SD_BUS_NO_RESULT, m_servo, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("GetDistance", SD_BUS_ARGS("y", sensor), SD_BUS_RESULT("q", millimeters), m_distance,
                                   kUnpriv)),
    property<[](C c) { const auto& o = c.telemetry().orientation; return std::tuple{o[0], o[1], o[2]}; }>("Orientation", kChange, kTick),
    property<[](C c) -> const auto& { return c.telemetry().distances; }>("Distances", kChange, kTick),
    property<[](C c) -> const auto& { return c.telemetry().servos; }>("Servos", kChange, kTick),
    property<[](C c) { return c.telemetry().turning ? "turning" : "idle"; }>("Task", kChange, kTick),
    property<[](C c) { return c.telemetry().online; }>("Online", kChange, kTick),
    property<[](C c) { return c.counters().frames; }>("Frames", kChange, kCounterTick), // every poll: 1 Hz
    property<[](C c) { return c.counters().busy_retries; }>("BusyRetries", kChange, kTick),
    property<[](C c) { return c.counters().link_errors; }>("LinkErrors", kChange, kTick),
};
constexpr auto kVtable = vtable(kMembers);

} // namespace

TeensyObject::TeensyObject(sd_bus* bus, TeensyPort& teensy)
    : object_(bus, kTeensyPath, kTeensyIface, kMembers, kVtable, &teensy) {}

} // namespace caracara::dbus
