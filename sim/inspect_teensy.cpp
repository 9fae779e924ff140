#include "sim/inspect_teensy.hpp"

#include "drivers/sdbus/property.hpp"
#include "sim/inspect_reply.hpp"
#include "sim/sim_vehicle.hpp"

#include <cmath>
#include <string>
#include <tuple>

namespace caracara::sim {

namespace {

using dbus::kUnpriv;
using dbus::member;
using dbus::property;

TeensyModel& teensy(void* userdata) { return static_cast<SimVehicle*>(userdata)->teensy(); }

int m_inject(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    const char* kind = nullptr;
    uint32_t frames = 0;
    if (int r = sd_bus_message_read(m, "su", &kind, &frames); r < 0)
        return r;
    const std::string k = kind;
    if (k == "busy")
        teensy(userdata).faults().inject_busy(frames);
    else if (k == "garbage-ack")
        teensy(userdata).faults().inject_garbage_ack(frames);
    else if (k == "no-answer")
        teensy(userdata).faults().inject_no_answer(frames);
    else
        return sd_bus_error_setf(err, kInspectInvalid, "fault must be busy, garbage-ack or no-answer, got '%s'", kind);
    return sd_bus_reply_method_return(m, "");
}

int m_random_busy(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    double p = 0;
    uint64_t seed = 0;
    if (int r = sd_bus_message_read(m, "dt", &p, &seed); r < 0)
        return r;
    if (!teensy(userdata).faults().set_random_busy(p, seed))
        return sd_bus_error_setf(err, kInspectInvalid, "probability must be within 0..1");
    return sd_bus_reply_method_return(m, "");
}

// A hung Teensy (or its SPI controller): every message is answered `ms` late; 0 ends it.
int m_set_hang(sd_bus_message* m, void* userdata, sd_bus_error*) {
    uint32_t ms = 0;
    if (int r = sd_bus_message_read(m, "u", &ms); r < 0)
        return r;
    static_cast<SimVehicle*>(userdata)->teensy_port().hang_ms = ms;
    return sd_bus_reply_method_return(m, "");
}

int m_clear(sd_bus_message* m, void* userdata, sd_bus_error*) {
    teensy(userdata).faults().clear();
    static_cast<SimVehicle*>(userdata)->teensy_port().hang_ms = 0;
    return sd_bus_reply_method_return(m, "");
}

int m_set_distance(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    uint8_t sensor = 0;
    uint16_t mm = 0;
    if (int r = sd_bus_message_read(m, "yq", &sensor, &mm); r < 0)
        return r;
    if (!teensy(userdata).set_distance_mm(sensor, mm))
        return sd_bus_error_setf(err, kInspectInvalid, "no distance sensor %u", sensor);
    return sd_bus_reply_method_return(m, "");
}

int m_commands(sd_bus_message* m, void* userdata, sd_bus_error*) {
    uint8_t cmd = 0;
    if (int r = sd_bus_message_read(m, "y", &cmd); r < 0)
        return r;
    return sd_bus_reply_method_return(m, "tt", static_cast<uint64_t>(teensy(userdata).frames().commands_received(cmd)),
                                      static_cast<uint64_t>(teensy(userdata).frames().commands_executed(cmd)));
}

// Place(x, y, depth, yaw, pitch, roll): the vehicle put somewhere, at rest (sim/vehicle_body.hpp's
// world and angles), so that a test can start a motion below the surface or turned.
int m_place(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    double x = 0, y = 0, depth = 0, yaw = 0, pitch = 0, roll = 0;
    if (int r = sd_bus_message_read(m, "dddddd", &x, &y, &depth, &yaw, &pitch, &roll); r < 0)
        return r;
    for (double v : {x, y, depth, yaw, pitch, roll})
        if (!std::isfinite(v))
            return sd_bus_error_setf(err, kInspectInvalid, "a place must be finite numbers");
    if (depth < 0)
        return sd_bus_error_setf(err, kInspectInvalid, "depth must be 0 or more (the surface is 0), got %g", depth);
    VehicleBody& body = static_cast<SimVehicle*>(userdata)->body();
    body.set_position({x, y, depth});
    body.set_attitude({yaw, pitch, roll});
    return sd_bus_reply_method_return(m, "");
}

// GetFrameLog() -> a(tttysayay): seq, start_ns, end_ns, command, outcome, mosi, miso.
int m_frame_log(sd_bus_message* m, void* userdata, sd_bus_error*) {
    return reply_with(m, [&](sd_bus_message* reply) {
        int r = sd_bus_message_open_container(reply, 'a', "(tttysayay)");
        for (const auto& f : teensy(userdata).frames().records()) {
            if (r >= 0) r = sd_bus_message_open_container(reply, 'r', "tttysayay");
            if (r >= 0) r = sd_bus_message_append(reply, "tttys", f.seq, f.start_ns, f.end_ns, f.command, std::string(name_of(f.outcome)).c_str());
            if (r >= 0) r = sd_bus_message_append_array(reply, 'y', f.mosi.data(), f.mosi.size());
            if (r >= 0) r = sd_bus_message_append_array(reply, 'y', f.miso.data(), f.miso.size());
            if (r >= 0) r = sd_bus_message_close_container(reply);
        }
        return r < 0 ? r : sd_bus_message_close_container(reply);
    });
}

using V = SimVehicle&;
SpiPort& spi(V v) { return v.teensy_port(); }

constexpr dbus::Member kMembers[] = {
    property<[](V v) { auto o = v.teensy().orientation(); return std::tuple{o.yaw, o.pitch, o.roll}; }>("Orientation"),
    property<[](V v) { auto p = v.body().position(); return std::tuple{p.x, p.y, p.depth}; }>("Position"),
    property<[](V v) { auto w = v.body().velocity(); return std::tuple{w.x, w.y, w.depth}; }>("Velocity"),
    property<[](V v) {
        auto w = v.teensy().wheels();
        return std::tuple{w.front_left, w.front_right, w.back_left, w.back_right};
    }>("Wheels"),
    property<[](V v) { auto l = v.teensy().leds(); return std::tuple{l[0], l[1], l[2]}; }>("Leds"),
    property<[](V v) -> const auto& { return v.teensy().servo_degrees(); }>("Servos"),
    property<[](V v) -> const auto& { return v.teensy().distances_mm(); }>("Distances"),
    property<[](V v) { return v.teensy().stop_duty(); }>("StopDuty"),
    property<[](V v) { return name_of(v.teensy().task_state()); }>("Task"),
    property<[](V v) { return v.teensy().acknowledgements(); }>("Acknowledgements"),
    property<[](V v) { return v.teensy().frames().total(); }>("Frames"),
    property<[](V v) { return double(v.teensy().last_turn_rad()); }>("LastTurn"),
    property<[](V v) { return double(v.teensy().last_turn_to_rad()); }>("LastTurnTo"),
    property<[](V v) { return v.teensy().heading_offset(); }>("HeadingOffset"),
    property<[](V v) { return spi(v).mode; }>("SpiMode"),
    property<[](V v) { return spi(v).bits_per_word; }>("SpiBitsPerWord"),
    property<[](V v) { return spi(v).max_speed_hz; }>("SpiMaxSpeedHz"),
    property<[](V v) { return spi(v).mode_mismatches; }>("SpiModeMismatches"),
    property<[](V v) { return spi(v).last_transfers; }>("SpiLastTransfers"),
    property<[](V v) { return spi(v).last_speed_hz; }>("SpiLastSpeedHz"),
    property<[](V v) { return spi(v).last_delay_usecs; }>("SpiLastDelayUsecs"),
    property<[](V v) { return spi(v).hang_ms; }>("HangMs"),
    member(SD_BUS_METHOD_WITH_ARGS("InjectFault", SD_BUS_ARGS("s", fault, "u", frames), SD_BUS_NO_RESULT, m_inject, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("SetRandomBusy", SD_BUS_ARGS("d", probability, "t", seed), SD_BUS_NO_RESULT, m_random_busy,
                                   kUnpriv)),
    member(SD_BUS_METHOD("ClearFaults", "", "", m_clear, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("SetHang", SD_BUS_ARGS("u", ms), SD_BUS_NO_RESULT, m_set_hang, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("SetDistance", SD_BUS_ARGS("y", sensor, "q", millimeters), SD_BUS_NO_RESULT, m_set_distance,
                                   kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("CommandCount", SD_BUS_ARGS("y", command), SD_BUS_RESULT("t", received, "t", executed),
                                   m_commands, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("Place", SD_BUS_ARGS("d", x, "d", y, "d", depth, "d", yaw, "d", pitch, "d", roll),
                                   SD_BUS_NO_RESULT, m_place, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("GetFrameLog", SD_BUS_NO_ARGS, SD_BUS_RESULT("a(tttysayay)", frames), m_frame_log, kUnpriv)),
};
constexpr auto kVtable = dbus::vtable(kMembers);

} // namespace

const sd_bus_vtable* teensy_inspection() { return kVtable.data(); }

} // namespace caracara::sim
