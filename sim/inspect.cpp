#include "inspect.hpp"

#include "device_server.hpp"

#include <cerrno>
#include <string>

namespace caracara::sim {

namespace {

constexpr const char* kRoot = "/org/caracara/Simulator1";
constexpr const char* kErrInvalid = "org.caracara.Simulator1.Error.InvalidArgument";

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
// read, data, miso, result.
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
    SD_BUS_METHOD_WITH_ARGS("GetWireLog", SD_BUS_ARGS("t", since), SD_BUS_RESULT("t", next, "a(tttsqbayays)", entries), m_wire_log, 0),
    SD_BUS_METHOD("ClearWireLog", "", "", m_clear_log, 0),
    SD_BUS_METHOD_WITH_ARGS("SetRealisticTiming", SD_BUS_ARGS("b", enabled), SD_BUS_NO_RESULT, m_set_realistic, 0),
    SD_BUS_METHOD_WITH_ARGS("SetClock", SD_BUS_ARGS("u", hz), SD_BUS_NO_RESULT, m_set_clock, 0),
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
    SD_BUS_METHOD_WITH_ARGS("SetFault", SD_BUS_ARGS("s", fault, "b", on), SD_BUS_NO_RESULT, m_set_fault, 0),
    SD_BUS_METHOD_WITH_ARGS("SetNack", SD_BUS_ARGS("b", on), SD_BUS_NO_RESULT, m_set_nack, 0),
    SD_BUS_METHOD_WITH_ARGS("CorruptReplies", SD_BUS_ARGS("u", count, "s", how), SD_BUS_NO_RESULT, m_corrupt, 0),
    SD_BUS_METHOD("PowerCycle", "", "", m_power_cycle, 0),
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
    return sd_bus_request_name(bus_, "org.caracara.Simulator1", 0);
}

} // namespace caracara::sim
