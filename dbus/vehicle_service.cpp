#include "dbus/vehicle_service.hpp"

#include "protocol/seabotix.hpp"

#include <array>
#include <cerrno>
#include <cstring>
#include <memory>

namespace caracara::dbus {

namespace {

VehicleDaemon& ctl(void* userdata) { return static_cast<VehicleService*>(userdata)->controller(); }
VehicleService::ThrusterObject& tobj(void* userdata) { return *static_cast<VehicleService::ThrusterObject*>(userdata); }
const ThrusterDriver& thr(void* userdata) {
    auto& o = tobj(userdata);
    return o.service->controller().bus().thruster(o.index);
}

// Status fields of either controller variant, as the Thruster interface presents them.
uint8_t actual_speed(const ThrusterStatus& s) {
    if (s.variant == Variant::SeaBotix)
        return s.seabotix.speed;
    return s.legacy.max_power_meaning == MaxPowerMeaning::PowerSpeed ? s.legacy.max_power : uint8_t{0x80};
}
double current_amps(const ThrusterStatus& s) { return s.current_deciamps ? *s.current_deciamps / 10.0 : 0.0; }
double temperature_c(const ThrusterStatus& s) {
    return s.variant == Variant::SeaBotix ? static_cast<double>(s.seabotix.temperature_c) : 0.0;
}
uint8_t firmware_revision(const ThrusterStatus& s) {
    return s.variant == Variant::SeaBotix ? s.seabotix.firmware_revision : s.legacy.revision_code;
}
std::string thruster_error_text(const ThrusterDriver& t) {
    if (t.last_error() == IoError::None)
        return "";
    if (t.last_error() == IoError::BadReply)
        return std::string(codec_error_name(t.last_reply_error()));
    return std::string(io_error_name(t.last_error()));
}

int reply_result(sd_bus_message* m, const Result& r, sd_bus_error* err) {
    if (!r.ok()) {
        const std::string name = std::string(kErrorPrefix) + std::string(status_name(r.status));
        return sd_bus_error_set(err, name.c_str(), r.message.c_str());
    }
    return sd_bus_reply_method_return(m, "");
}

std::string sender(sd_bus_message* m) {
    const char* s = sd_bus_message_get_sender(m);
    return s ? s : "";
}

int read_int_array(sd_bus_message* m, std::vector<int32_t>& out) {
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

int append_ints(sd_bus_message* reply, const MotorValues& v) {
    return sd_bus_message_append_array(reply, 'i', v.data(), v.size() * sizeof(int32_t));
}

// The names of the properties that changed, nullptr-terminated, without a heap allocation.
class ChangedNames {
public:
    void add(const char* name) {
        if (n_ + 1 < names_.size())
            names_[n_++] = name;
    }
    bool empty() const { return n_ == 0; }
    const char* const* get() {
        names_[n_] = nullptr;
        return names_.data();
    }

private:
    std::array<const char*, 24> names_{};
    size_t n_ = 0;
};

// PropertiesChanged for `names` (nullptr-terminated) of one object, filled by the vtable's own
// getters. sd_bus_emit_properties_changed_strv() produces the same signal but finds every
// property through the bus's object tree and hash tables first: about 27 000 instructions a
// signal, most of the daemon's steady cost. Only EMITS_CHANGE properties with getters are
// announced here; an unknown name is a programming error and sends nothing.
int emit_properties_changed(sd_bus* bus, const char* path, const char* iface, const sd_bus_vtable* vtable,
                            void* userdata, const char* const* names) {
    if (!names || !*names)
        return 0;
    sd_bus_message* raw = nullptr;
    int r = sd_bus_message_new_signal(bus, &raw, path, "org.freedesktop.DBus.Properties", "PropertiesChanged");
    if (r < 0)
        return r;
    MessagePtr m(raw);
    if ((r = sd_bus_message_append(raw, "s", iface)) < 0 || (r = sd_bus_message_open_container(raw, 'a', "{sv}")) < 0)
        return r;
    for (const char* const* name = names; *name; ++name) {
        const sd_bus_vtable* v = vtable;
        while (v->type != _SD_BUS_VTABLE_END &&
               !(v->type == _SD_BUS_VTABLE_PROPERTY && std::strcmp(v->x.property.member, *name) == 0))
            ++v;
        if (v->type == _SD_BUS_VTABLE_END || !v->x.property.get || !(v->flags & SD_BUS_VTABLE_PROPERTY_EMITS_CHANGE))
            return -EINVAL;
        if ((r = sd_bus_message_open_container(raw, 'e', "sv")) < 0 ||
            (r = sd_bus_message_append_basic(raw, 's', *name)) < 0 ||
            (r = sd_bus_message_open_container(raw, 'v', v->x.property.signature)) < 0)
            return r;
        sd_bus_error error = SD_BUS_ERROR_NULL;
        r = v->x.property.get(bus, path, iface, *name, raw, userdata, &error);
        sd_bus_error_free(&error);
        if (r < 0 || (r = sd_bus_message_close_container(raw)) < 0 || (r = sd_bus_message_close_container(raw)) < 0)
            return r;
    }
    if ((r = sd_bus_message_close_container(raw)) < 0 || (r = sd_bus_message_append(raw, "as", 0)) < 0)
        return r;
    return sd_bus_send(bus, raw, nullptr);
}

#define PROP(name) \
    int name(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata, sd_bus_error*)

// --- Vehicle -------------------------------------------------------------------------------

int m_set_thrust(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    std::vector<int32_t> v;
    if (int r = read_int_array(m, v); r < 0)
        return r;
    return reply_result(m, ctl(userdata).vehicle().set_thrust(v, sender(m)), err);
}

int m_set_motion(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    AxisDemand d{};
    int r = sd_bus_message_read(m, "dddddd", &d[0], &d[1], &d[2], &d[3], &d[4], &d[5]);
    if (r < 0)
        return r;
    return reply_result(m, ctl(userdata).vehicle().set_motion(d, sender(m)), err);
}

int m_apply_packet(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    std::vector<int32_t> v;
    if (int r = read_int_array(m, v); r < 0)
        return r;
    return reply_result(m, ctl(userdata).vehicle().apply_packet(v, sender(m)), err);
}

int m_kill(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    return reply_result(m, ctl(userdata).vehicle().kill(KillSource::DBus, "Kill() from " + sender(m)), err);
}

int m_clear_kill(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    return reply_result(m, ctl(userdata).vehicle().clear_kill(), err);
}

int m_power_off(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    const char* confirmation = nullptr;
    int r = sd_bus_message_read(m, "s", &confirmation);
    if (r < 0)
        return r;
    return reply_result(m, ctl(userdata).vehicle().power_off(confirmation), err);
}

int m_set_leds(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    uint8_t red = 0, green = 0, blue = 0;
    int r = sd_bus_message_read(m, "yyy", &red, &green, &blue);
    if (r < 0)
        return r;
    return reply_result(m, ctl(userdata).vehicle().set_leds(red, green, blue), err);
}

PROP(p_state) { return sd_bus_message_append(reply, "s", std::string(ctl(userdata).vehicle().state_name()).c_str()); }
PROP(p_kill_source) { return sd_bus_message_append(reply, "s", std::string(ctl(userdata).vehicle().kill_source_name()).c_str()); }
PROP(p_motor_values) { return append_ints(reply, ctl(userdata).vehicle().motor_values()); }
PROP(p_requested_values) { return append_ints(reply, ctl(userdata).vehicle().requested_values()); }
PROP(p_budget_limit) { return sd_bus_message_append(reply, "i", ctl(userdata).vehicle().budget_limit()); }
PROP(p_saturated) { return sd_bus_message_append(reply, "b", static_cast<int>(ctl(userdata).vehicle().saturated())); }
PROP(p_policy) {
    return sd_bus_message_append(reply, "s", std::string(policy_name(ctl(userdata).config().control.budget_policy)).c_str());
}
PROP(p_leds) {
    auto l = ctl(userdata).teensy().leds();
    return sd_bus_message_append(reply, "(yyy)", l[0], l[1], l[2]);
}
PROP(p_command_age) { return sd_bus_message_append(reply, "x", ctl(userdata).vehicle().command_age_ms()); }
PROP(p_controller) { return sd_bus_message_append(reply, "s", ctl(userdata).vehicle().controller_client().c_str()); }
PROP(p_timeout) { return sd_bus_message_append(reply, "u", ctl(userdata).config().control.command_timeout_ms); }
PROP(p_arming) { return sd_bus_message_append(reply, "u", ctl(userdata).config().control.arming_delay_ms); }
PROP(p_rate) { return sd_bus_message_append(reply, "d", static_cast<double>(ctl(userdata).config().control.loop_rate_hz)); }
PROP(p_cycles) { return sd_bus_message_append(reply, "t", ctl(userdata).loop().cycles()); }

constexpr uint64_t kUnpriv = SD_BUS_VTABLE_UNPRIVILEGED; // access is the bus policy's job
constexpr uint64_t kChange = SD_BUS_VTABLE_PROPERTY_EMITS_CHANGE;
constexpr uint64_t kConst = SD_BUS_VTABLE_PROPERTY_CONST;

const sd_bus_vtable kVehicleVtable[] = {
    SD_BUS_VTABLE_START(0),
    SD_BUS_METHOD_WITH_ARGS("SetThrust", SD_BUS_ARGS("ai", values), SD_BUS_NO_RESULT, m_set_thrust, kUnpriv),
    SD_BUS_METHOD_WITH_ARGS("SetMotion", SD_BUS_ARGS("d", x, "d", y, "d", z, "d", yaw, "d", pitch, "d", roll),
                            SD_BUS_NO_RESULT, m_set_motion, kUnpriv),
    SD_BUS_METHOD_WITH_ARGS("ApplyPacket", SD_BUS_ARGS("ai", packet), SD_BUS_NO_RESULT, m_apply_packet, kUnpriv),
    SD_BUS_METHOD("Kill", "", "", m_kill, kUnpriv),
    SD_BUS_METHOD("ClearKill", "", "", m_clear_kill, kUnpriv),
    SD_BUS_METHOD_WITH_ARGS("PowerOff", SD_BUS_ARGS("s", confirmation), SD_BUS_NO_RESULT, m_power_off, kUnpriv),
    SD_BUS_METHOD_WITH_ARGS("SetLeds", SD_BUS_ARGS("y", red, "y", green, "y", blue), SD_BUS_NO_RESULT, m_set_leds, kUnpriv),
    SD_BUS_PROPERTY("State", "s", p_state, 0, kChange),
    SD_BUS_PROPERTY("KillSource", "s", p_kill_source, 0, kChange),
    SD_BUS_PROPERTY("MotorValues", "ai", p_motor_values, 0, kChange),
    SD_BUS_PROPERTY("RequestedValues", "ai", p_requested_values, 0, kChange),
    SD_BUS_PROPERTY("BudgetLimit", "i", p_budget_limit, 0, kChange),
    SD_BUS_PROPERTY("Saturated", "b", p_saturated, 0, kChange),
    SD_BUS_PROPERTY("BudgetPolicy", "s", p_policy, 0, kConst),
    SD_BUS_PROPERTY("Leds", "(yyy)", p_leds, 0, kChange),
    SD_BUS_PROPERTY("CommandAgeMs", "x", p_command_age, 0, kChange),
    SD_BUS_PROPERTY("Controller", "s", p_controller, 0, kChange),
    SD_BUS_PROPERTY("CommandTimeoutMs", "u", p_timeout, 0, kConst),
    SD_BUS_PROPERTY("ArmingDelayMs", "u", p_arming, 0, kConst),
    SD_BUS_PROPERTY("LoopRateHz", "d", p_rate, 0, kConst),
    SD_BUS_PROPERTY("Cycles", "t", p_cycles, 0, kChange),
    SD_BUS_VTABLE_END,
};

// --- Thruster ------------------------------------------------------------------------------

PROP(t_index) { return sd_bus_message_append(reply, "u", static_cast<uint32_t>(tobj(userdata).index)); }
PROP(t_address) { return sd_bus_message_append(reply, "y", thr(userdata).config().mt); }
PROP(t_variant) { return sd_bus_message_append(reply, "s", std::string(variant_name(thr(userdata).config().variant)).c_str()); }
PROP(t_mux_address) {
    const auto& mux = thr(userdata).config().mux;
    return sd_bus_message_append(reply, "q", static_cast<uint16_t>(mux ? mux->addr7 : 0));
}
PROP(t_mux_channel) {
    const auto& mux = thr(userdata).config().mux;
    return sd_bus_message_append(reply, "i", mux ? static_cast<int32_t>(mux->channel) : -1);
}
PROP(t_reversed) { return sd_bus_message_append(reply, "b", static_cast<int>(thr(userdata).config().reversed)); }
PROP(t_online) { return sd_bus_message_append(reply, "b", static_cast<int>(thr(userdata).online())); }
PROP(t_ordered_value) {
    auto& o = tobj(userdata);
    return sd_bus_message_append(reply, "i", o.service->controller().bus().ordered_value(o.index));
}
PROP(t_ordered_speed) { return sd_bus_message_append(reply, "y", thr(userdata).last_speed().value_or(0x80)); }
PROP(t_actual_speed) {
    const auto& s = thr(userdata).last_status();
    return sd_bus_message_append(reply, "y", s ? actual_speed(*s) : uint8_t{0x80});
}
PROP(t_current) {
    const auto& s = thr(userdata).last_status();
    return sd_bus_message_append(reply, "d", s ? current_amps(*s) : 0.0);
}
PROP(t_temperature) {
    const auto& s = thr(userdata).last_status();
    return sd_bus_message_append(reply, "d", s ? temperature_c(*s) : 0.0);
}
PROP(t_faults) {
    int r = sd_bus_message_open_container(reply, 'a', "s");
    const auto& s = thr(userdata).last_status();
    if (s)
        for (Fault f : kAllFaults)
            if (r >= 0 && s->faults.has(f))
                r = sd_bus_message_append(reply, "s", std::string(fault_name(f)).c_str());
    return r < 0 ? r : sd_bus_message_close_container(reply);
}
PROP(t_firmware) {
    const auto& s = thr(userdata).last_status();
    return sd_bus_message_append(reply, "y", s ? firmware_revision(*s) : uint8_t{0});
}
PROP(t_orders) { return sd_bus_message_append(reply, "t", thr(userdata).counters().orders_sent); }
PROP(t_failures) { return sd_bus_message_append(reply, "t", thr(userdata).counters().order_failures); }
PROP(t_reads) { return sd_bus_message_append(reply, "t", thr(userdata).counters().status_reads); }
PROP(t_nacks) { return sd_bus_message_append(reply, "t", thr(userdata).counters().nacks); }
PROP(t_timeouts) { return sd_bus_message_append(reply, "t", thr(userdata).counters().timeouts); }
PROP(t_bad) { return sd_bus_message_append(reply, "t", thr(userdata).counters().bad_replies); }
PROP(t_last_error) { return sd_bus_message_append(reply, "s", thruster_error_text(thr(userdata)).c_str()); }

const sd_bus_vtable kThrusterVtable[] = {
    SD_BUS_VTABLE_START(0),
    SD_BUS_PROPERTY("Index", "u", t_index, 0, kConst),
    SD_BUS_PROPERTY("Address", "y", t_address, 0, kConst),
    SD_BUS_PROPERTY("Variant", "s", t_variant, 0, kConst),
    SD_BUS_PROPERTY("MuxAddress", "q", t_mux_address, 0, kConst),
    SD_BUS_PROPERTY("MuxChannel", "i", t_mux_channel, 0, kConst),
    SD_BUS_PROPERTY("Reversed", "b", t_reversed, 0, kConst),
    SD_BUS_PROPERTY("Online", "b", t_online, 0, kChange),
    SD_BUS_PROPERTY("OrderedValue", "i", t_ordered_value, 0, kChange),
    SD_BUS_PROPERTY("OrderedSpeed", "y", t_ordered_speed, 0, kChange),
    SD_BUS_PROPERTY("ActualSpeed", "y", t_actual_speed, 0, kChange),
    SD_BUS_PROPERTY("Current", "d", t_current, 0, kChange),
    SD_BUS_PROPERTY("Temperature", "d", t_temperature, 0, kChange),
    SD_BUS_PROPERTY("Faults", "as", t_faults, 0, kChange),
    SD_BUS_PROPERTY("FirmwareRevision", "y", t_firmware, 0, kChange),
    SD_BUS_PROPERTY("OrdersSent", "t", t_orders, 0, kChange),
    SD_BUS_PROPERTY("OrderFailures", "t", t_failures, 0, kChange),
    SD_BUS_PROPERTY("StatusReads", "t", t_reads, 0, kChange),
    SD_BUS_PROPERTY("Nacks", "t", t_nacks, 0, kChange),
    SD_BUS_PROPERTY("Timeouts", "t", t_timeouts, 0, kChange),
    SD_BUS_PROPERTY("BadReplies", "t", t_bad, 0, kChange),
    SD_BUS_PROPERTY("LastError", "s", t_last_error, 0, kChange),
    SD_BUS_VTABLE_END,
};

// --- Teensy --------------------------------------------------------------------------------

int m_t_set_speed(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    int32_t l = 0, r2 = 0;
    int r = sd_bus_message_read(m, "ii", &l, &r2);
    if (r < 0)
        return r;
    return reply_result(m, ctl(userdata).teensy().set_speed(l, r2), err);
}

int m_t_stop(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    uint8_t duty = 0;
    int r = sd_bus_message_read(m, "y", &duty);
    if (r < 0)
        return r;
    return reply_result(m, ctl(userdata).teensy().stop(duty), err);
}

int m_t_servo(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    uint8_t id = 0, deg = 0;
    int r = sd_bus_message_read(m, "yy", &id, &deg);
    if (r < 0)
        return r;
    return reply_result(m, ctl(userdata).teensy().servo(id, deg), err);
}

int m_t_distance(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    uint8_t id = 0;
    int r = sd_bus_message_read(m, "y", &id);
    if (r < 0)
        return r;
    uint16_t mm = 0;
    Result res = ctl(userdata).teensy().distance(id, mm);
    if (!res.ok())
        return reply_result(m, res, err);
    return sd_bus_reply_method_return(m, "q", mm);
}

int turn(sd_bus_message* m, void* userdata, sd_bus_error* err, bool absolute) {
    double rad = 0;
    int r = sd_bus_message_read(m, "d", &rad);
    if (r < 0)
        return r;
    // Reply later, when the Teensy confirms; other calls are served meanwhile.
    sd_bus_message_ref(m);
    auto pending = std::shared_ptr<sd_bus_message>(m, sd_bus_message_unref);
    Result res = ctl(userdata).teensy().turn(rad, absolute, [pending](const Result& done) {
        if (done.ok()) {
            sd_bus_reply_method_return(pending.get(), "");
        } else {
            const std::string name = std::string(kErrorPrefix) + std::string(status_name(done.status));
            sd_bus_reply_method_errorf(pending.get(), name.c_str(), "%s", done.message.c_str());
        }
    });
    if (!res.ok())
        return reply_result(m, res, err);
    return 1;
}

int m_t_turn(sd_bus_message* m, void* userdata, sd_bus_error* err) { return turn(m, userdata, err, false); }
int m_t_turn_to(sd_bus_message* m, void* userdata, sd_bus_error* err) { return turn(m, userdata, err, true); }

PROP(te_orientation) {
    const auto& o = ctl(userdata).teensy().telemetry().orientation;
    return sd_bus_message_append(reply, "(ddd)", o[0], o[1], o[2]);
}
PROP(te_distances) {
    const auto& d = ctl(userdata).teensy().telemetry().distances;
    return sd_bus_message_append_array(reply, 'q', d.data(), d.size() * sizeof(uint16_t));
}
PROP(te_servos) {
    const auto& s = ctl(userdata).teensy().telemetry().servos;
    return sd_bus_message_append_array(reply, 'y', s.data(), s.size());
}
PROP(te_task) { return sd_bus_message_append(reply, "s", ctl(userdata).teensy().telemetry().turning ? "turning" : "idle"); }
PROP(te_online) { return sd_bus_message_append(reply, "b", static_cast<int>(ctl(userdata).teensy().telemetry().online)); }
PROP(te_frames) { return sd_bus_message_append(reply, "t", ctl(userdata).teensy().counters().frames); }
PROP(te_busy) { return sd_bus_message_append(reply, "t", ctl(userdata).teensy().counters().busy_retries); }
PROP(te_errors) { return sd_bus_message_append(reply, "t", ctl(userdata).teensy().counters().link_errors); }

const sd_bus_vtable kTeensyVtable[] = {
    SD_BUS_VTABLE_START(0),
    SD_BUS_METHOD_WITH_ARGS("SetSpeed", SD_BUS_ARGS("i", left, "i", right), SD_BUS_NO_RESULT, m_t_set_speed, kUnpriv),
    SD_BUS_METHOD_WITH_ARGS("Turn", SD_BUS_ARGS("d", radians), SD_BUS_NO_RESULT, m_t_turn, kUnpriv),
    SD_BUS_METHOD_WITH_ARGS("TurnTo", SD_BUS_ARGS("d", heading), SD_BUS_NO_RESULT, m_t_turn_to, kUnpriv),
    SD_BUS_METHOD_WITH_ARGS("Stop", SD_BUS_ARGS("y", brake_duty), SD_BUS_NO_RESULT, m_t_stop, kUnpriv),
    SD_BUS_METHOD_WITH_ARGS("SetServo", SD_BUS_ARGS("y", id, "y", degrees), SD_BUS_NO_RESULT, m_t_servo, kUnpriv),
    SD_BUS_METHOD_WITH_ARGS("GetDistance", SD_BUS_ARGS("y", sensor), SD_BUS_RESULT("q", millimeters), m_t_distance, kUnpriv),
    SD_BUS_PROPERTY("Orientation", "(ddd)", te_orientation, 0, kChange),
    SD_BUS_PROPERTY("Distances", "aq", te_distances, 0, kChange),
    SD_BUS_PROPERTY("Servos", "ay", te_servos, 0, kChange),
    SD_BUS_PROPERTY("Task", "s", te_task, 0, kChange),
    SD_BUS_PROPERTY("Online", "b", te_online, 0, kChange),
    SD_BUS_PROPERTY("Frames", "t", te_frames, 0, kChange),
    SD_BUS_PROPERTY("BusyRetries", "t", te_busy, 0, kChange),
    SD_BUS_PROPERTY("LinkErrors", "t", te_errors, 0, kChange),
    SD_BUS_VTABLE_END,
};

// --- Bus -------------------------------------------------------------------------------------

PROP(b_device) { return sd_bus_message_append(reply, "s", ctl(userdata).config().i2c.device.c_str()); }
PROP(b_state) { return sd_bus_message_append(reply, "s", std::string(bus_state_name(ctl(userdata).bus().telemetry().state)).c_str()); }
PROP(b_transactions) { return sd_bus_message_append(reply, "t", ctl(userdata).bus().telemetry().transactions); }
PROP(b_errors) { return sd_bus_message_append(reply, "t", ctl(userdata).bus().telemetry().errors); }
PROP(b_last_error) { return sd_bus_message_append(reply, "s", ctl(userdata).bus().telemetry().last_error.c_str()); }
PROP(b_recoveries) { return sd_bus_message_append(reply, "t", ctl(userdata).bus().telemetry().recoveries); }
PROP(b_failures) { return sd_bus_message_append(reply, "t", ctl(userdata).bus().telemetry().recovery_failures); }
PROP(b_pulses) { return sd_bus_message_append(reply, "u", ctl(userdata).bus().telemetry().last_pulses); }
PROP(b_recovery_ms) { return sd_bus_message_append(reply, "d", ctl(userdata).bus().telemetry().last_recovery_ms); }
PROP(b_recovery_error) { return sd_bus_message_append(reply, "s", ctl(userdata).bus().telemetry().last_recovery_error.c_str()); }

const sd_bus_vtable kBusVtable[] = {
    SD_BUS_VTABLE_START(0),
    SD_BUS_PROPERTY("Device", "s", b_device, 0, kConst),
    SD_BUS_PROPERTY("State", "s", b_state, 0, kChange),
    SD_BUS_PROPERTY("Transactions", "t", b_transactions, 0, kChange),
    SD_BUS_PROPERTY("Errors", "t", b_errors, 0, kChange),
    SD_BUS_PROPERTY("LastError", "s", b_last_error, 0, kChange),
    SD_BUS_PROPERTY("Recoveries", "t", b_recoveries, 0, kChange),
    SD_BUS_PROPERTY("RecoveryFailures", "t", b_failures, 0, kChange),
    SD_BUS_PROPERTY("LastPulses", "u", b_pulses, 0, kChange),
    SD_BUS_PROPERTY("LastRecoveryMs", "d", b_recovery_ms, 0, kChange),
    SD_BUS_PROPERTY("LastRecoveryError", "s", b_recovery_error, 0, kChange),
    SD_BUS_SIGNAL_WITH_ARGS("BusLost", SD_BUS_ARGS("s", reason), 0),
    SD_BUS_SIGNAL_WITH_ARGS("BusRestored", SD_BUS_ARGS("u", pulses, "d", milliseconds), 0),
    SD_BUS_VTABLE_END,
};

#undef PROP

} // namespace

VehicleService::~VehicleService() {
    if (bus_)
        sd_bus_release_name(bus_, kBusName);
}

int VehicleService::start() {
    sd_bus_slot* slot = nullptr;
    auto keep = [&](int r) {
        if (r >= 0)
            slots_.emplace_back(slot);
        return r;
    };
    int r = keep(sd_bus_add_object_manager(bus_, &slot, kRootPath));
    if (r >= 0)
        r = keep(sd_bus_add_object_vtable(bus_, &slot, kRootPath, kVehicleIface, kVehicleVtable, this));
    for (size_t i = 0; r >= 0 && i < controller_.bus().size(); ++i) {
        auto obj = std::make_unique<ThrusterObject>(
            ThrusterObject{this, i, std::string(kRootPath) + "/thruster/" + std::to_string(i)});
        r = keep(sd_bus_add_object_vtable(bus_, &slot, obj->path.c_str(), kThrusterIface, kThrusterVtable, obj.get()));
        thruster_objects_.push_back(std::move(obj));
    }
    if (r >= 0)
        r = keep(sd_bus_add_object_vtable(bus_, &slot, kTeensyPath, kTeensyIface,
                                          kTeensyVtable, this));
    if (r >= 0)
        r = keep(sd_bus_add_object_vtable(bus_, &slot, kBusPath, kBusIface,
                                          kBusVtable, this));
    // Track every disconnect from the start, so a controlling client that leaves right after
    // its command cannot slip past an asynchronously installed match.
    if (r >= 0)
        r = keep(sd_bus_add_match(bus_, &slot,
                                  "type='signal',sender='org.freedesktop.DBus',path='/org/freedesktop/DBus',"
                                  "interface='org.freedesktop.DBus',member='NameOwnerChanged'",
                                  on_name_owner_changed, this));
    if (r < 0)
        return r;
    for (size_t i = 0; i < controller_.bus().size(); ++i)
        published_.push_back(snapshot(i));
    return sd_bus_request_name(bus_, kBusName, 0);
}

int VehicleService::on_name_owner_changed(sd_bus_message* m, void* userdata, sd_bus_error*) {
    const char *name = nullptr, *old_owner = nullptr, *new_owner = nullptr;
    if (sd_bus_message_read(m, "sss", &name, &old_owner, &new_owner) < 0)
        return 0;
    if (name && name[0] == ':' && new_owner && new_owner[0] == '\0')
        static_cast<VehicleService*>(userdata)->controller_.vehicle().client_left(name);
    return 0;
}

void VehicleService::vehicle_changed(uint32_t changes) { announce(changes, false); }

void VehicleService::telemetry() { announce(0, true); }

void VehicleService::announce(uint32_t changes, bool telemetry) {
    // Announced once the reply and the orders of the change (or the tick's) have gone out,
    // coalesced: see kAnnouncePriority.
    pending_ |= changes;
    telemetry_pending_ = telemetry_pending_ || telemetry;
    sd_event* ev = sd_bus_get_event(bus_);
    if (!flush_ && ev) {
        sd_event_source* s = nullptr;
        if (sd_event_add_defer(ev, &s, on_flush, this) >= 0) {
            flush_.reset(s);
            sd_event_source_set_priority(s, kAnnouncePriority);
        }
    }
    if (flush_)
        sd_event_source_set_enabled(flush_.get(), SD_EVENT_ONESHOT);
    else
        on_flush(nullptr, this); // no event loop to defer to: now
}

int VehicleService::on_flush(sd_event_source*, void* userdata) {
    auto* self = static_cast<VehicleService*>(userdata);
    const uint32_t c = self->pending_;
    const bool telemetry = self->telemetry_pending_;
    self->pending_ = 0;
    self->telemetry_pending_ = false;
    self->emit_vehicle_changes(c);
    if (telemetry)
        self->emit_telemetry();
    return 0;
}

void VehicleService::emit_vehicle_changes(uint32_t changes) {
    ChangedNames names;
    if (changes & kChangeState) {
        names.add("State");
        names.add("KillSource");
    }
    if (changes & kChangeMotors) {
        names.add("MotorValues");
        names.add("RequestedValues");
        names.add("BudgetLimit");
        names.add("Saturated");
    }
    if (changes & kChangeLeds)
        names.add("Leds");
    if (changes & kChangeController)
        names.add("Controller");
    if (changes & kChangeBus)
        emit_bus_changes();
    if (names.empty())
        return;
    emit_properties_changed(bus_, kRootPath, kVehicleIface, kVehicleVtable, this, names.get());
}

VehicleService::ThrusterSnapshot VehicleService::snapshot(size_t i) const {
    const ThrusterDriver& t = controller_.bus().thruster(i);
    ThrusterSnapshot s;
    s.online = t.online();
    s.ordered_value = controller_.bus().ordered_value(i);
    s.ordered_speed = t.last_speed().value_or(0x80);
    if (const auto& st = t.last_status()) {
        s.actual_speed = actual_speed(*st);
        s.current = current_amps(*st);
        s.temperature = temperature_c(*st);
        s.faults = st->faults.bits;
        s.firmware = firmware_revision(*st);
    }
    const auto& c = t.counters();
    s.orders = c.orders_sent;
    s.failures = c.order_failures;
    s.reads = c.status_reads;
    s.nacks = c.nacks;
    s.timeouts = c.timeouts;
    s.bad = c.bad_replies;
    s.last_error = thruster_error_text(t);
    return s;
}

void VehicleService::emit_telemetry() {
    counters_due_ = (++publications_ % 5) == 0;
    const char* const vehicle_names[] = {"CommandAgeMs", "Cycles", nullptr};
    emit_properties_changed(bus_, kRootPath, kVehicleIface, kVehicleVtable, this, vehicle_names);

    for (size_t i = 0; i < thruster_objects_.size(); ++i) {
        ThrusterSnapshot now = snapshot(i);
        if (!counters_due_) {
            // Steady counters (one more order every tick) are announced at 1 Hz, not 5 Hz.
            now.orders = published_[i].orders;
            now.reads = published_[i].reads;
        }
        const ThrusterSnapshot& was = published_[i];
        if (now == was)
            continue;
        ChangedNames n;
        if (now.online != was.online) n.add("Online");
        if (now.ordered_value != was.ordered_value) n.add("OrderedValue");
        if (now.ordered_speed != was.ordered_speed) n.add("OrderedSpeed");
        if (now.actual_speed != was.actual_speed) n.add("ActualSpeed");
        if (now.current != was.current) n.add("Current");
        if (now.temperature != was.temperature) n.add("Temperature");
        if (now.faults != was.faults) n.add("Faults");
        if (now.firmware != was.firmware) n.add("FirmwareRevision");
        if (now.orders != was.orders) n.add("OrdersSent");
        if (now.failures != was.failures) n.add("OrderFailures");
        if (now.reads != was.reads) n.add("StatusReads");
        if (now.nacks != was.nacks) n.add("Nacks");
        if (now.timeouts != was.timeouts) n.add("Timeouts");
        if (now.bad != was.bad) n.add("BadReplies");
        if (now.last_error != was.last_error) n.add("LastError");
        emit_properties_changed(bus_, thruster_objects_[i]->path.c_str(), kThrusterIface, kThrusterVtable,
                                thruster_objects_[i].get(), n.get());
        published_[i] = std::move(now);
    }

    const TeensyTelemetry& te = controller_.teensy().telemetry();
    const auto& tc = controller_.teensy().counters();
    ChangedNames tn;
    if (te.orientation != published_teensy_.orientation) tn.add("Orientation");
    if (te.distances != published_teensy_.distances) tn.add("Distances");
    if (te.servos != published_teensy_.servos) tn.add("Servos");
    if (te.turning != published_teensy_.turning) tn.add("Task");
    if (te.online != published_teensy_.online) tn.add("Online");
    if (counters_due_ && tc.frames != published_teensy_frames_) tn.add("Frames");
    if (tc.busy_retries != published_teensy_busy_) tn.add("BusyRetries");
    if (tc.link_errors != published_teensy_errors_) tn.add("LinkErrors");
    if (!tn.empty()) {
        emit_properties_changed(bus_, kTeensyPath, kTeensyIface, kTeensyVtable, this, tn.get());
        published_teensy_ = te;
        if (counters_due_)
            published_teensy_frames_ = tc.frames;
        published_teensy_busy_ = tc.busy_retries;
        published_teensy_errors_ = tc.link_errors;
    }

    emit_bus_changes();
}

void VehicleService::emit_bus_changes() {
    const BusTelemetry& b = controller_.bus().telemetry();
    ChangedNames bn;
    if (b.state != published_bus_.state) bn.add("State");
    if (counters_due_ && b.transactions != published_bus_.transactions) bn.add("Transactions");
    if (b.errors != published_bus_.errors) bn.add("Errors");
    if (b.last_error != published_bus_.last_error) bn.add("LastError");
    if (b.recoveries != published_bus_.recoveries) bn.add("Recoveries");
    if (b.recovery_failures != published_bus_.recovery_failures) bn.add("RecoveryFailures");
    if (b.last_pulses != published_bus_.last_pulses) bn.add("LastPulses");
    if (b.last_recovery_ms != published_bus_.last_recovery_ms) bn.add("LastRecoveryMs");
    if (b.last_recovery_error != published_bus_.last_recovery_error) bn.add("LastRecoveryError");
    if (bn.empty())
        return;
    emit_properties_changed(bus_, kBusPath, kBusIface, kBusVtable, this, bn.get());
    published_bus_ = b;
}

void VehicleService::bus_lost(const std::string& reason) {
    sd_bus_emit_signal(bus_, kBusPath, kBusIface, "BusLost", "s", reason.c_str());
}

void VehicleService::bus_restored(uint32_t pulses, double milliseconds) {
    sd_bus_emit_signal(bus_, kBusPath, kBusIface, "BusRestored", "ud", pulses,
                       milliseconds);
}

} // namespace caracara::dbus
