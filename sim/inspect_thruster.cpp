#include "sim/inspect_thruster.hpp"

#include "drivers/sdbus/property.hpp"
#include "sim/inspect_reply.hpp"
#include "sim/thruster_model.hpp"

#include <string>

namespace caracara::sim {

namespace {

using dbus::kConst;
using dbus::kUnpriv;
using dbus::member;
using dbus::property;

ThrusterModel& thruster(void* userdata) { return *static_cast<ThrusterModel*>(userdata); }

int m_set_fault(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    const char* name = nullptr;
    int on = 0;
    if (int r = sd_bus_message_read(m, "sb", &name, &on); r < 0)
        return r;
    auto bit = fault_bit_from_name(name);
    if (!bit)
        return sd_bus_error_setf(err, kInspectInvalid,
                                 "unknown fault '%s' (overtemp, stall, hall, ground-fault, water-detect)", name);
    thruster(userdata).set_fault(*bit, on);
    return sd_bus_reply_method_return(m, "");
}

int m_set_nack(sd_bus_message* m, void* userdata, sd_bus_error*) {
    int on = 0;
    if (int r = sd_bus_message_read(m, "b", &on); r < 0)
        return r;
    thruster(userdata).set_nack(on);
    return sd_bus_reply_method_return(m, "");
}

int m_corrupt(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    uint32_t count = 0;
    const char* how = nullptr;
    if (int r = sd_bus_message_read(m, "us", &count, &how); r < 0)
        return r;
    const std::string h = how;
    if (h != "checksum" && h != "first-byte")
        return sd_bus_error_setf(err, kInspectInvalid, "corruption must be 'checksum' or 'first-byte', got '%s'", how);
    thruster(userdata).corrupt_replies(count, h == "checksum" ? ThrusterModel::Corrupt::Checksum
                                                             : ThrusterModel::Corrupt::FirstByte);
    return sd_bus_reply_method_return(m, "");
}

int m_set_hang(sd_bus_message* m, void* userdata, sd_bus_error*) {
    uint32_t ms = 0;
    if (int r = sd_bus_message_read(m, "u", &ms); r < 0)
        return r;
    thruster(userdata).set_hang_ms(ms);
    return sd_bus_reply_method_return(m, "");
}

// The motor's temperature and the water's it tends to: water at the motor's temperature holds it
// there (a stopped motor does not heat), for overtemp's 110/100 C hysteresis (SeaBotix IDS
// 8.4.2 remark 6).
int m_set_temperature(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    double motor = 0, water = 0;
    if (int r = sd_bus_message_read(m, "dd", &motor, &water); r < 0)
        return r;
    if (!(motor >= -5 && motor <= 255 && water >= -5 && water <= 255))
        return sd_bus_error_setf(err, kInspectInvalid, "temperatures must be -5..255 C");
    thruster(userdata).set_temperature(motor);
    thruster(userdata).set_water_temperature(water);
    return sd_bus_reply_method_return(m, "");
}

int m_power_cycle(sd_bus_message* m, void* userdata, sd_bus_error*) {
    thruster(userdata).power_cycle();
    return sd_bus_reply_method_return(m, "");
}

using T = const ThrusterModel&;

constexpr dbus::Member kMembers[] = {
    property<[](T t) { return t.spec().mt; }>("Address", kConst),
    property<[](T t) { return t.spec().variant == ThrusterVariant::SeaBotix ? "seabotix" : "legacy"; }>("Variant", kConst),
    property<[](T t) { return uint16_t(t.spec().mux_addr.value_or(0)); }>("MuxAddress", kConst),
    property<[](T t) { return t.spec().mux_addr ? int32_t(t.spec().mux_channel) : -1; }>("MuxChannel", kConst),
    property<&ThrusterModel::last_order_raw>("LastOrder"),
    property<&ThrusterModel::last_order_time_ns>("LastOrderTimeNs"),
    property<&ThrusterModel::ordered_speed>("OrderedSpeed"),
    property<&ThrusterModel::info>("Info"),
    property<&ThrusterModel::actual_speed_byte>("ActualSpeed"),
    property<&ThrusterModel::current_a>("Current"),
    property<&ThrusterModel::temperature_c>("Temperature"),
    property<[](T t) { return fault_names(t.faults()); }>("Faults"),
    property<&ThrusterModel::nack>("Nack"),
    property<&ThrusterModel::hang_ms>("HangMs"),
    property<&ThrusterModel::orders_received>("OrdersReceived"),
    property<&ThrusterModel::orders_rejected>("OrdersRejected"),
    property<&ThrusterModel::zero_orders>("ZeroOrders"),
    property<&ThrusterModel::status_reads>("StatusReads"),
    member(SD_BUS_METHOD_WITH_ARGS("SetFault", SD_BUS_ARGS("s", fault, "b", on), SD_BUS_NO_RESULT, m_set_fault, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("SetNack", SD_BUS_ARGS("b", on), SD_BUS_NO_RESULT, m_set_nack, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("CorruptReplies", SD_BUS_ARGS("u", count, "s", how), SD_BUS_NO_RESULT, m_corrupt, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("SetHang", SD_BUS_ARGS("u", ms), SD_BUS_NO_RESULT, m_set_hang, kUnpriv)),
    member(SD_BUS_METHOD("PowerCycle", "", "", m_power_cycle, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("SetTemperature", SD_BUS_ARGS("d", motor, "d", water), SD_BUS_NO_RESULT,
                                   m_set_temperature, kUnpriv)),
};
constexpr auto kVtable = dbus::vtable(kMembers);

} // namespace

const sd_bus_vtable* thruster_inspection() { return kVtable.data(); }

} // namespace caracara::sim
