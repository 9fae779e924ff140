#include "dbus/teensy_object.hpp"

#include "dbus/announcer.hpp"
#include "dbus/error_reply.hpp"
#include "dbus/vehicle_names.hpp"

#include <memory>
#include <tuple>

namespace caracara::dbus {

namespace {

TeensyPort& teensy(void* userdata) { return *static_cast<TeensyPort*>(userdata); }

// Every Teensy command is carried by its worker: replied to when the Teensy answered (other
// calls are served meanwhile), or at once when refused before anything was sent.
int reply_when_done(sd_bus_message* m, const Result& started) { return started.ok() ? 1 : reply(m, started); }

int m_set_speed(sd_bus_message* m, void* userdata, sd_bus_error*) {
    int32_t left = 0, right = 0;
    if (int r = sd_bus_message_read(m, "ii", &left, &right); r < 0)
        return r;
    return reply_when_done(m, teensy(userdata).set_speed(left, right, sender(m), reply_later(m)));
}

int m_stop(sd_bus_message* m, void* userdata, sd_bus_error*) {
    uint8_t duty = 0;
    if (int r = sd_bus_message_read(m, "y", &duty); r < 0)
        return r;
    return reply_when_done(m, teensy(userdata).stop(duty, reply_later(m)));
}

int m_servo(sd_bus_message* m, void* userdata, sd_bus_error*) {
    uint8_t id = 0, degrees = 0;
    if (int r = sd_bus_message_read(m, "yy", &id, &degrees); r < 0)
        return r;
    return reply_when_done(m, teensy(userdata).servo(id, degrees, reply_later(m)));
}

int m_distance(sd_bus_message* m, void* userdata, sd_bus_error*) {
    uint8_t sensor = 0;
    if (int r = sd_bus_message_read(m, "y", &sensor); r < 0)
        return r;
    auto held = std::shared_ptr<sd_bus_message>(sd_bus_message_ref(m), sd_bus_message_unref);
    return reply_when_done(m, teensy(userdata).distance(sensor, [held](const Result& res, uint16_t mm) {
        if (!res.ok())
            reply(held.get(), res);
        else
            sd_bus_reply_method_return(held.get(), "q", mm);
    }));
}

int turn(sd_bus_message* m, void* userdata, bool absolute) {
    double radians = 0;
    if (int r = sd_bus_message_read(m, "d", &radians); r < 0)
        return r;
    // Replied to when the Teensy confirms; other calls are served meanwhile.
    return reply_when_done(m, teensy(userdata).turn(radians, absolute, sender(m), reply_later(m)));
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
    property<[](C c) { return c.telemetry().orientation_read_ns; }>("OrientationReadNs", kChange, kTick),
    property<[](C c) -> const auto& { return c.telemetry().distances; }>("Distances", kChange, kTick),
    property<[](C c) -> const auto& { return c.telemetry().servos; }>("Servos", kChange, kTick),
    property<[](C c) { return c.telemetry().turning ? "turning" : "idle"; }>("Task", kChange, kTick),
    property<[](C c) { return c.telemetry().online; }>("Online", kChange, kTick),
    property<[](C c) { return name_of(c.loss()); }>("LinkLoss", kChange, kTick),
    property<[](C c) { return c.counters().frames; }>("Frames", kChange, kCounterTick), // every poll: 1 Hz
    property<[](C c) { return c.counters().busy_retries; }>("BusyRetries", kChange, kTick),
    property<[](C c) { return c.counters().link_errors; }>("LinkErrors", kChange, kTick),
};
constexpr auto kVtable = vtable(kMembers);

} // namespace

TeensyObject::TeensyObject(sd_bus* bus, TeensyPort& teensy)
    : object_(bus, kTeensyPath, kTeensyIface, kMembers, kVtable, &teensy) {}

} // namespace caracara::dbus
