#include "sim/inspect.hpp"

#include "sim/device_server.hpp"

#include <cerrno>
#include <string>

namespace caracara::sim {

namespace {

constexpr const char* kRoot = "/org/caracara/Simulator1";
constexpr const char* kErrInvalid = "org.caracara.Simulator1.Error.InvalidArgument";
// Who may call what is the bus policy's job (systemd/org.caracara.Simulator1.conf): without
// this flag sd-bus itself refuses every caller that is neither root nor the service's user.
constexpr uint64_t kMethod = SD_BUS_VTABLE_UNPRIVILEGED;

ThrusterModel& thruster(void* userdata) { return *static_cast<ThrusterModel*>(userdata); }
Inspector& insp(void* userdata) { return *static_cast<Inspector*>(userdata); }

#define GETTER(name, type, expr)                                                                               \
    int name(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata, sd_bus_error*) { \
        return sd_bus_message_append(reply, type, expr);                                                       \
    }

GETTER(get_clock, "u", insp(userdata).vehicle().i2c().clock_hz())
GETTER(get_realistic, "b", static_cast<int>(insp(userdata).vehicle().realistic_timing()))
GETTER(get_transactions, "t", static_cast<uint64_t>(insp(userdata).vehicle().i2c().transactions()))
GETTER(get_wire_time, "t", static_cast<uint64_t>(insp(userdata).vehicle().i2c().wire_time_ns()))
GETTER(get_thruster_count, "u", static_cast<uint32_t>(insp(userdata).vehicle().thrusters().size()))
GETTER(get_bad_requests, "t", static_cast<uint64_t>(insp(userdata).server().bad_requests()))
GETTER(get_clients, "u", static_cast<uint32_t>(insp(userdata).server().clients()))

GETTER(get_kill_switch, "b", static_cast<int>(insp(userdata).vehicle().gpio().kill_switch_engaged()))
GETTER(get_kill_switch_active_low, "b", static_cast<int>(insp(userdata).vehicle().gpio().kill_switch_active_low()))
GETTER(get_kill_output, "b", static_cast<int>(insp(userdata).vehicle().gpio().level(GpioModel::kKillOut)))
GETTER(get_power_off_output, "b", static_cast<int>(insp(userdata).vehicle().gpio().level(GpioModel::kPowerOff)))
GETTER(get_scl, "b", static_cast<int>(insp(userdata).vehicle().gpio().level(GpioModel::kScl)))
GETTER(get_sda, "b", static_cast<int>(insp(userdata).vehicle().gpio().level(GpioModel::kSda)))
GETTER(get_i2c_function, "b", static_cast<int>(insp(userdata).vehicle().i2c().i2c_function()))
GETTER(get_bound, "b", static_cast<int>(insp(userdata).vehicle().driver_bound()))
GETTER(get_unbinds, "t", static_cast<uint64_t>(insp(userdata).vehicle().unbinds()))
GETTER(get_binds, "t", static_cast<uint64_t>(insp(userdata).vehicle().binds()))
GETTER(get_scl_pulses, "t", static_cast<uint64_t>(insp(userdata).vehicle().gpio().scl_pulses()))
GETTER(get_stops, "t", static_cast<uint64_t>(insp(userdata).vehicle().gpio().stops()))
GETTER(get_min_scl_period, "t", static_cast<uint64_t>(insp(userdata).vehicle().gpio().min_scl_period_ns()))
GETTER(get_hang_seen, "u", insp(userdata).vehicle().i2c().hang_pulses_seen())
GETTER(get_hang_needed, "u", insp(userdata).vehicle().i2c().hang_pulses_needed())

GETTER(t_address, "y", thruster(userdata).spec().mt)
GETTER(t_variant, "s", thruster(userdata).spec().variant == ThrusterVariant::SeaBotix ? "seabotix" : "legacy")
GETTER(t_mux_address, "q", static_cast<uint16_t>(thruster(userdata).spec().mux_addr.value_or(0)))
GETTER(t_mux_channel, "i", thruster(userdata).spec().mux_addr ? static_cast<int32_t>(thruster(userdata).spec().mux_channel) : -1)
GETTER(t_ordered, "y", thruster(userdata).ordered_speed())
GETTER(t_info, "y", thruster(userdata).info())
GETTER(t_actual, "y", thruster(userdata).actual_speed_byte())
GETTER(t_current, "d", thruster(userdata).current_a())
GETTER(t_temperature, "d", thruster(userdata).temperature_c())
GETTER(t_nack, "b", static_cast<int>(thruster(userdata).nack()))
GETTER(t_orders, "t", static_cast<uint64_t>(thruster(userdata).orders_received()))
GETTER(t_rejected, "t", static_cast<uint64_t>(thruster(userdata).orders_rejected()))
GETTER(t_reads, "t", static_cast<uint64_t>(thruster(userdata).status_reads()))
GETTER(t_zero_orders, "t", static_cast<uint64_t>(thruster(userdata).zero_orders()))
GETTER(t_last_order_time, "t", static_cast<uint64_t>(thruster(userdata).last_order_time_ns()))
#undef GETTER

int get_kill_switch_line(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void*, sd_bus_error*) {
    return sd_bus_message_append(reply, "u", static_cast<uint32_t>(GpioModel::kKillSwitch));
}

int get_hang(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata, sd_bus_error*) {
    switch (insp(userdata).vehicle().i2c().hang()) {
    case I2cBusModel::Hang::None: return sd_bus_message_append(reply, "s", "none");
    case I2cBusModel::Hang::SdaLow: return sd_bus_message_append(reply, "s", "sda-low");
    case I2cBusModel::Hang::SclLow: return sd_bus_message_append(reply, "s", "scl-low");
    }
    return -EINVAL;
}

int m_set_kill_switch(sd_bus_message* m, void* userdata, sd_bus_error*) {
    int on = 0;
    int r = sd_bus_message_read(m, "b", &on);
    if (r < 0)
        return r;
    insp(userdata).vehicle().gpio().set_kill_switch(on, monotonic_ns());
    return sd_bus_reply_method_return(m, "");
}

int m_hang_bus(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    uint32_t pulses = 0;
    int r = sd_bus_message_read(m, "u", &pulses);
    if (r < 0)
        return r;
    if (pulses < 1 || pulses > 9)
        return sd_bus_error_setf(err, kErrInvalid, "a slave holds SDA for 1..9 clock pulses, got %u", pulses);
    insp(userdata).vehicle().i2c().hang_sda(pulses);
    return sd_bus_reply_method_return(m, "");
}

int m_hold_scl(sd_bus_message* m, void* userdata, sd_bus_error*) {
    insp(userdata).vehicle().i2c().hang_scl();
    return sd_bus_reply_method_return(m, "");
}

int m_release_bus(sd_bus_message* m, void* userdata, sd_bus_error*) {
    insp(userdata).vehicle().i2c().clear_hang();
    return sd_bus_reply_method_return(m, "");
}

int t_last_order(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata, sd_bus_error*) {
    const auto& raw = thruster(userdata).last_order_raw();
    return sd_bus_message_append_array(reply, 'y', raw.data(), raw.size());
}

int t_faults(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata, sd_bus_error*) {
    int r = sd_bus_message_open_container(reply, 'a', "s");
    for (const auto& n : fault_names(thruster(userdata).faults()))
        if (r >= 0)
            r = sd_bus_message_append(reply, "s", n.c_str());
    return r < 0 ? r : sd_bus_message_close_container(reply);
}

int m_set_fault(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    const char* name = nullptr;
    int on = 0;
    int r = sd_bus_message_read(m, "sb", &name, &on);
    if (r < 0)
        return r;
    auto bit = fault_bit_from_name(name);
    if (!bit)
        return sd_bus_error_setf(err, kErrInvalid,
                                 "unknown fault '%s' (overtemp, stall, hall, ground-fault, water-detect)", name);
    thruster(userdata).set_fault(*bit, on);
    return sd_bus_reply_method_return(m, "");
}

int m_set_nack(sd_bus_message* m, void* userdata, sd_bus_error*) {
    int on = 0;
    int r = sd_bus_message_read(m, "b", &on);
    if (r < 0)
        return r;
    thruster(userdata).set_nack(on);
    return sd_bus_reply_method_return(m, "");
}

int m_corrupt(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    uint32_t count = 0;
    const char* how = nullptr;
    int r = sd_bus_message_read(m, "us", &count, &how);
    if (r < 0)
        return r;
    std::string h = how;
    if (h != "checksum" && h != "first-byte")
        return sd_bus_error_setf(err, kErrInvalid, "corruption must be 'checksum' or 'first-byte', got '%s'", how);
    thruster(userdata).corrupt_replies(count, h == "checksum" ? ThrusterModel::Corrupt::Checksum
                                                             : ThrusterModel::Corrupt::FirstByte);
    return sd_bus_reply_method_return(m, "");
}

int m_power_cycle(sd_bus_message* m, void* userdata, sd_bus_error*) {
    thruster(userdata).power_cycle();
    return sd_bus_reply_method_return(m, "");
}

// GetWireLog(t since) -> (t next, a(tttsqbayays)): index, time_ns, transaction, bus, addr,
// read, data, miso, result (the kinds of entry are in wire_log.hpp). bus "i2c" and "spi" are
// transactions; "i2c-lines" are recovery line events; "gpio" is a GPIO line level change:
// addr = the line offset (KillSwitchLine for the kill switch), data = {new level on the wire},
// result "edge", time_ns = the moment of the change (for the kill switch, the moment
// SetKillSwitch changed it, which is when caracarad's edge event can fire).
int m_wire_log(sd_bus_message* m, void* userdata, sd_bus_error*) {
    uint64_t since = 0;
    int r = sd_bus_message_read(m, "t", &since);
    if (r < 0)
        return r;
    sd_bus_message* reply = nullptr;
    r = sd_bus_message_new_method_return(m, &reply);
    if (r < 0)
        return r;
    dbus::MessagePtr guard(reply);
    auto& log = insp(userdata).vehicle().log();
    r = sd_bus_message_append(reply, "t", log.next_index());
    if (r >= 0)
        r = sd_bus_message_open_container(reply, 'a', "(tttsqbayays)");
    for (const WireEntry* e : log.since(since)) {
        if (r >= 0) r = sd_bus_message_open_container(reply, 'r', "tttsqbayays");
        if (r >= 0) r = sd_bus_message_append(reply, "tttsqb", e->index, e->time_ns, e->transaction, e->bus.c_str(), e->addr, static_cast<int>(e->read));
        if (r >= 0) r = sd_bus_message_append_array(reply, 'y', e->data.data(), e->data.size());
        if (r >= 0) r = sd_bus_message_append_array(reply, 'y', e->miso.data(), e->miso.size());
        if (r >= 0) r = sd_bus_message_append(reply, "s", e->result.c_str());
        if (r >= 0) r = sd_bus_message_close_container(reply);
    }
    if (r >= 0)
        r = sd_bus_message_close_container(reply);
    if (r < 0)
        return r;
    return sd_bus_send(nullptr, reply, nullptr);
}

int m_clear_log(sd_bus_message* m, void* userdata, sd_bus_error*) {
    insp(userdata).vehicle().log().clear();
    return sd_bus_reply_method_return(m, "");
}

int m_set_realistic(sd_bus_message* m, void* userdata, sd_bus_error*) {
    int on = 0;
    int r = sd_bus_message_read(m, "b", &on);
    if (r < 0)
        return r;
    insp(userdata).vehicle().set_realistic_timing(on);
    return sd_bus_reply_method_return(m, "");
}

int m_set_clock(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    uint32_t hz = 0;
    int r = sd_bus_message_read(m, "u", &hz);
    if (r < 0)
        return r;
    if (hz < 1000 || hz > 3400000)
        return sd_bus_error_setf(err, kErrInvalid, "clock must be 1000..3400000 Hz, got %u", hz);
    insp(userdata).vehicle().i2c().set_clock_hz(hz);
    return sd_bus_reply_method_return(m, "");
}

const sd_bus_vtable kRootVtable[] = {
    SD_BUS_VTABLE_START(0),
    SD_BUS_PROPERTY("ClockHz", "u", get_clock, 0, 0),
    SD_BUS_PROPERTY("RealisticTiming", "b", get_realistic, 0, 0),
    SD_BUS_PROPERTY("Transactions", "t", get_transactions, 0, 0),
    SD_BUS_PROPERTY("WireTimeNs", "t", get_wire_time, 0, 0),
    SD_BUS_PROPERTY("ThrusterCount", "u", get_thruster_count, 0, SD_BUS_VTABLE_PROPERTY_CONST),
    SD_BUS_PROPERTY("BadRequests", "t", get_bad_requests, 0, 0),
    SD_BUS_PROPERTY("Clients", "u", get_clients, 0, 0),
    SD_BUS_METHOD_WITH_ARGS("GetWireLog", SD_BUS_ARGS("t", since), SD_BUS_RESULT("t", next, "a(tttsqbayays)", entries), m_wire_log, kMethod),
    SD_BUS_METHOD("ClearWireLog", "", "", m_clear_log, kMethod),
    SD_BUS_METHOD_WITH_ARGS("SetRealisticTiming", SD_BUS_ARGS("b", enabled), SD_BUS_NO_RESULT, m_set_realistic, kMethod),
    SD_BUS_METHOD_WITH_ARGS("SetClock", SD_BUS_ARGS("u", hz), SD_BUS_NO_RESULT, m_set_clock, kMethod),
    SD_BUS_PROPERTY("KillSwitch", "b", get_kill_switch, 0, 0),
    SD_BUS_PROPERTY("KillSwitchLine", "u", get_kill_switch_line, 0, SD_BUS_VTABLE_PROPERTY_CONST),
    SD_BUS_PROPERTY("KillSwitchActiveLow", "b", get_kill_switch_active_low, 0, SD_BUS_VTABLE_PROPERTY_CONST),
    SD_BUS_PROPERTY("KillOutput", "b", get_kill_output, 0, 0),
    SD_BUS_PROPERTY("PowerOffOutput", "b", get_power_off_output, 0, 0),
    SD_BUS_PROPERTY("Scl", "b", get_scl, 0, 0),
    SD_BUS_PROPERTY("Sda", "b", get_sda, 0, 0),
    SD_BUS_PROPERTY("I2cFunction", "b", get_i2c_function, 0, 0),
    SD_BUS_PROPERTY("DriverBound", "b", get_bound, 0, 0),
    SD_BUS_PROPERTY("Unbinds", "t", get_unbinds, 0, 0),
    SD_BUS_PROPERTY("Binds", "t", get_binds, 0, 0),
    SD_BUS_PROPERTY("BusHang", "s", get_hang, 0, 0),
    SD_BUS_PROPERTY("HangPulsesSeen", "u", get_hang_seen, 0, 0),
    SD_BUS_PROPERTY("HangPulsesNeeded", "u", get_hang_needed, 0, 0),
    SD_BUS_PROPERTY("SclPulses", "t", get_scl_pulses, 0, 0),
    SD_BUS_PROPERTY("Stops", "t", get_stops, 0, 0),
    SD_BUS_PROPERTY("MinSclPeriodNs", "t", get_min_scl_period, 0, 0),
    SD_BUS_METHOD_WITH_ARGS("SetKillSwitch", SD_BUS_ARGS("b", engaged), SD_BUS_NO_RESULT, m_set_kill_switch, kMethod),
    SD_BUS_METHOD_WITH_ARGS("HangBus", SD_BUS_ARGS("u", pulses), SD_BUS_NO_RESULT, m_hang_bus, kMethod),
    SD_BUS_METHOD("HoldScl", "", "", m_hold_scl, kMethod),
    SD_BUS_METHOD("ReleaseBus", "", "", m_release_bus, kMethod),
    SD_BUS_VTABLE_END,
};

const sd_bus_vtable kThrusterVtable[] = {
    SD_BUS_VTABLE_START(0),
    SD_BUS_PROPERTY("Address", "y", t_address, 0, SD_BUS_VTABLE_PROPERTY_CONST),
    SD_BUS_PROPERTY("Variant", "s", t_variant, 0, SD_BUS_VTABLE_PROPERTY_CONST),
    SD_BUS_PROPERTY("MuxAddress", "q", t_mux_address, 0, SD_BUS_VTABLE_PROPERTY_CONST),
    SD_BUS_PROPERTY("MuxChannel", "i", t_mux_channel, 0, SD_BUS_VTABLE_PROPERTY_CONST),
    SD_BUS_PROPERTY("LastOrder", "ay", t_last_order, 0, 0),
    SD_BUS_PROPERTY("LastOrderTimeNs", "t", t_last_order_time, 0, 0),
    SD_BUS_PROPERTY("OrderedSpeed", "y", t_ordered, 0, 0),
    SD_BUS_PROPERTY("Info", "y", t_info, 0, 0),
    SD_BUS_PROPERTY("ActualSpeed", "y", t_actual, 0, 0),
    SD_BUS_PROPERTY("Current", "d", t_current, 0, 0),
    SD_BUS_PROPERTY("Temperature", "d", t_temperature, 0, 0),
    SD_BUS_PROPERTY("Faults", "as", t_faults, 0, 0),
    SD_BUS_PROPERTY("Nack", "b", t_nack, 0, 0),
    SD_BUS_PROPERTY("OrdersReceived", "t", t_orders, 0, 0),
    SD_BUS_PROPERTY("OrdersRejected", "t", t_rejected, 0, 0),
    SD_BUS_PROPERTY("ZeroOrders", "t", t_zero_orders, 0, 0),
    SD_BUS_PROPERTY("StatusReads", "t", t_reads, 0, 0),
    SD_BUS_METHOD_WITH_ARGS("SetFault", SD_BUS_ARGS("s", fault, "b", on), SD_BUS_NO_RESULT, m_set_fault, kMethod),
    SD_BUS_METHOD_WITH_ARGS("SetNack", SD_BUS_ARGS("b", on), SD_BUS_NO_RESULT, m_set_nack, kMethod),
    SD_BUS_METHOD_WITH_ARGS("CorruptReplies", SD_BUS_ARGS("u", count, "s", how), SD_BUS_NO_RESULT, m_corrupt, kMethod),
    SD_BUS_METHOD("PowerCycle", "", "", m_power_cycle, kMethod),
    SD_BUS_VTABLE_END,
};

// --- Teensy ---------------------------------------------------------------------------------

TeensyModel& teensy(void* userdata) { return insp(userdata).vehicle().teensy(); }

#define TGET(name, type, expr)                                                                                 \
    int name(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata, sd_bus_error*) { \
        return sd_bus_message_append(reply, type, expr);                                                       \
    }
TGET(te_task, "s", std::string(to_string(teensy(userdata).task_state())).c_str())
TGET(te_acks, "t", static_cast<uint64_t>(teensy(userdata).acknowledgements()))
TGET(te_frames, "t", static_cast<uint64_t>(teensy(userdata).frames_total()))
TGET(te_stop_duty, "y", teensy(userdata).stop_duty())
TGET(te_last_turn, "d", static_cast<double>(teensy(userdata).last_turn_rad()))
TGET(te_last_turn_to, "d", static_cast<double>(teensy(userdata).last_turn_to_rad()))
TGET(te_heading_offset, "d", teensy(userdata).heading_offset())
TGET(te_spi_mode, "y", insp(userdata).vehicle().teensy_port().mode)
TGET(te_spi_bits, "y", insp(userdata).vehicle().teensy_port().bits_per_word)
TGET(te_spi_speed, "u", insp(userdata).vehicle().teensy_port().max_speed_hz)
TGET(te_spi_mismatch, "t", static_cast<uint64_t>(insp(userdata).vehicle().teensy_port().mode_mismatches))
TGET(te_spi_last_transfers, "u", insp(userdata).vehicle().teensy_port().last_transfers)
TGET(te_spi_last_speed, "u", insp(userdata).vehicle().teensy_port().last_speed_hz)
TGET(te_spi_last_delay, "q", insp(userdata).vehicle().teensy_port().last_delay_usecs)
#undef TGET

int te_orientation(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata, sd_bus_error*) {
    auto o = teensy(userdata).orientation();
    return sd_bus_message_append(reply, "(ddd)", o.yaw, o.pitch, o.roll);
}
int te_position(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata, sd_bus_error*) {
    auto p = insp(userdata).vehicle().body().position();
    return sd_bus_message_append(reply, "(ddd)", p.x, p.y, p.depth);
}
int te_wheels(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata, sd_bus_error*) {
    auto w = teensy(userdata).wheels();
    return sd_bus_message_append(reply, "(dddd)", w.front_left, w.front_right, w.back_left, w.back_right);
}
int te_leds(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata, sd_bus_error*) {
    auto l = teensy(userdata).leds();
    return sd_bus_message_append(reply, "(yyy)", l[0], l[1], l[2]);
}
int te_servos(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata, sd_bus_error*) {
    const auto& v = teensy(userdata).servo_degrees();
    return sd_bus_message_append_array(reply, 'y', v.data(), v.size());
}
int te_distances(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata, sd_bus_error*) {
    const auto& v = teensy(userdata).distances_mm();
    return sd_bus_message_append_array(reply, 'q', v.data(), v.size() * sizeof(uint16_t));
}

int m_te_inject(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    const char* kind = nullptr;
    uint32_t frames = 0;
    int r = sd_bus_message_read(m, "su", &kind, &frames);
    if (r < 0)
        return r;
    std::string k = kind;
    if (k == "busy")
        teensy(userdata).inject_busy(frames);
    else if (k == "garbage-ack")
        teensy(userdata).inject_garbage_ack(frames);
    else if (k == "no-answer")
        teensy(userdata).inject_no_answer(frames);
    else
        return sd_bus_error_setf(err, kErrInvalid, "fault must be busy, garbage-ack or no-answer, got '%s'", kind);
    return sd_bus_reply_method_return(m, "");
}

int m_te_random_busy(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    double p = 0;
    uint64_t seed = 0;
    int r = sd_bus_message_read(m, "dt", &p, &seed);
    if (r < 0)
        return r;
    if (!teensy(userdata).set_random_busy(p, seed))
        return sd_bus_error_setf(err, kErrInvalid, "probability must be within 0..1");
    return sd_bus_reply_method_return(m, "");
}

int m_te_clear(sd_bus_message* m, void* userdata, sd_bus_error*) {
    teensy(userdata).clear_faults();
    return sd_bus_reply_method_return(m, "");
}

int m_te_set_distance(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    uint8_t sensor = 0;
    uint16_t mm = 0;
    int r = sd_bus_message_read(m, "yq", &sensor, &mm);
    if (r < 0)
        return r;
    if (!teensy(userdata).set_distance_mm(sensor, mm))
        return sd_bus_error_setf(err, kErrInvalid, "no distance sensor %u", sensor);
    return sd_bus_reply_method_return(m, "");
}

int m_te_commands(sd_bus_message* m, void* userdata, sd_bus_error*) {
    uint8_t cmd = 0;
    int r = sd_bus_message_read(m, "y", &cmd);
    if (r < 0)
        return r;
    return sd_bus_reply_method_return(m, "tt", static_cast<uint64_t>(teensy(userdata).commands_received(cmd)),
                                      static_cast<uint64_t>(teensy(userdata).commands_executed(cmd)));
}

// GetFrameLog() -> a(tttysayay): seq, start_ns, end_ns, command, outcome, mosi, miso.
int m_te_frame_log(sd_bus_message* m, void* userdata, sd_bus_error*) {
    sd_bus_message* reply = nullptr;
    int r = sd_bus_message_new_method_return(m, &reply);
    if (r < 0)
        return r;
    dbus::MessagePtr guard(reply);
    r = sd_bus_message_open_container(reply, 'a', "(tttysayay)");
    for (const auto& f : teensy(userdata).frame_log()) {
        if (r >= 0) r = sd_bus_message_open_container(reply, 'r', "tttysayay");
        if (r >= 0) r = sd_bus_message_append(reply, "tttys", f.seq, f.start_ns, f.end_ns, f.command, std::string(to_string(f.outcome)).c_str());
        if (r >= 0) r = sd_bus_message_append_array(reply, 'y', f.mosi.data(), f.mosi.size());
        if (r >= 0) r = sd_bus_message_append_array(reply, 'y', f.miso.data(), f.miso.size());
        if (r >= 0) r = sd_bus_message_close_container(reply);
    }
    if (r >= 0)
        r = sd_bus_message_close_container(reply);
    if (r < 0)
        return r;
    return sd_bus_send(nullptr, reply, nullptr);
}

const sd_bus_vtable kTeensyVtable[] = {
    SD_BUS_VTABLE_START(0),
    SD_BUS_PROPERTY("Orientation", "(ddd)", te_orientation, 0, 0),
    SD_BUS_PROPERTY("Position", "(ddd)", te_position, 0, 0),
    SD_BUS_PROPERTY("Wheels", "(dddd)", te_wheels, 0, 0),
    SD_BUS_PROPERTY("Leds", "(yyy)", te_leds, 0, 0),
    SD_BUS_PROPERTY("Servos", "ay", te_servos, 0, 0),
    SD_BUS_PROPERTY("Distances", "aq", te_distances, 0, 0),
    SD_BUS_PROPERTY("StopDuty", "y", te_stop_duty, 0, 0),
    SD_BUS_PROPERTY("Task", "s", te_task, 0, 0),
    SD_BUS_PROPERTY("Acknowledgements", "t", te_acks, 0, 0),
    SD_BUS_PROPERTY("Frames", "t", te_frames, 0, 0),
    SD_BUS_PROPERTY("LastTurn", "d", te_last_turn, 0, 0),
    SD_BUS_PROPERTY("LastTurnTo", "d", te_last_turn_to, 0, 0),
    SD_BUS_PROPERTY("HeadingOffset", "d", te_heading_offset, 0, 0),
    SD_BUS_PROPERTY("SpiMode", "y", te_spi_mode, 0, 0),
    SD_BUS_PROPERTY("SpiBitsPerWord", "y", te_spi_bits, 0, 0),
    SD_BUS_PROPERTY("SpiMaxSpeedHz", "u", te_spi_speed, 0, 0),
    SD_BUS_PROPERTY("SpiModeMismatches", "t", te_spi_mismatch, 0, 0),
    SD_BUS_PROPERTY("SpiLastTransfers", "u", te_spi_last_transfers, 0, 0),
    SD_BUS_PROPERTY("SpiLastSpeedHz", "u", te_spi_last_speed, 0, 0),
    SD_BUS_PROPERTY("SpiLastDelayUsecs", "q", te_spi_last_delay, 0, 0),
    SD_BUS_METHOD_WITH_ARGS("InjectFault", SD_BUS_ARGS("s", fault, "u", frames), SD_BUS_NO_RESULT, m_te_inject, kMethod),
    SD_BUS_METHOD_WITH_ARGS("SetRandomBusy", SD_BUS_ARGS("d", probability, "t", seed), SD_BUS_NO_RESULT, m_te_random_busy, kMethod),
    SD_BUS_METHOD("ClearFaults", "", "", m_te_clear, kMethod),
    SD_BUS_METHOD_WITH_ARGS("SetDistance", SD_BUS_ARGS("y", sensor, "q", millimeters), SD_BUS_NO_RESULT, m_te_set_distance, kMethod),
    SD_BUS_METHOD_WITH_ARGS("CommandCount", SD_BUS_ARGS("y", command), SD_BUS_RESULT("t", received, "t", executed), m_te_commands, kMethod),
    SD_BUS_METHOD_WITH_ARGS("GetFrameLog", SD_BUS_NO_ARGS, SD_BUS_RESULT("a(tttysayay)", frames), m_te_frame_log, kMethod),
    SD_BUS_VTABLE_END,
};

} // namespace

int Inspector::start() {
    sd_bus_slot* slot = nullptr;
    int r = sd_bus_add_object_manager(bus_, &slot, kRoot);
    if (r < 0)
        return r;
    slots_.emplace_back(slot);
    r = sd_bus_add_object_vtable(bus_, &slot, kRoot, "org.caracara.Simulator1", kRootVtable, this);
    if (r < 0)
        return r;
    slots_.emplace_back(slot);
    auto& ts = vehicle_.thrusters();
    for (size_t i = 0; i < ts.size(); ++i) {
        const std::string path = std::string(kRoot) + "/thruster/" + std::to_string(i);
        r = sd_bus_add_object_vtable(bus_, &slot, path.c_str(), "org.caracara.Simulator1.Thruster", kThrusterVtable,
                                     ts[i].get());
        if (r < 0)
            return r;
        slots_.emplace_back(slot);
    }
    r = sd_bus_add_object_vtable(bus_, &slot, (std::string(kRoot) + "/teensy").c_str(), "org.caracara.Simulator1.Teensy",
                                 kTeensyVtable, this);
    if (r < 0)
        return r;
    slots_.emplace_back(slot);
    return sd_bus_request_name(bus_, "org.caracara.Simulator1", 0);
}

} // namespace caracara::sim
