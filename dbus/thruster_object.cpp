#include "dbus/thruster_object.hpp"

#include "dbus/announcer.hpp"
#include "dbus/vehicle_names.hpp"
#include "drivers/protocol/seabotix.hpp"

#include <string>
#include <vector>

namespace caracara::dbus {

namespace {

// Status fields of either controller variant, as the Thruster interface presents them (0 where
// the variant's reply does not carry one).
double current_amps(const ThrusterStatus& s) { return s.current_deciamps ? *s.current_deciamps / 10.0 : 0.0; }
double temperature_c(const ThrusterStatus& s) { return s.temperature_c ? static_cast<double>(*s.temperature_c) : 0.0; }
uint8_t actual_speed(const ThrusterStatus& s) { return s.actual_speed; }
uint8_t firmware_revision(const ThrusterStatus& s) { return s.firmware_revision; }
std::vector<std::string> fault_names(const ThrusterStatus& s) {
    std::vector<std::string> names;
    for (Fault f : kAllFaults)
        if (s.faults.has(f))
            names.emplace_back(fault_name(f));
    return names;
}
std::string_view error_text(const ThrusterDriver& t) {
    if (t.last_error() == IoError::None)
        return "";
    if (t.last_error() == IoError::BadReply)
        return codec_error_name(t.last_reply_error());
    return io_error_name(t.last_error());
}

// The last status read through `f`, or `none` before the first one.
template <auto F>
auto status(const ThrusterObject& o, std::invoke_result_t<decltype(F), const ThrusterStatus&> none) {
    const auto& s = o.driver().last_status();
    return s ? F(*s) : none;
}

const ThrusterConfig& config(const ThrusterObject& o) { return o.driver().config(); }
const ThrusterCounters& counters(const ThrusterObject& o) { return o.driver().counters(); }

using O = const ThrusterObject&;
constexpr uint32_t kTick = kTelemetryTick;

constexpr Member kMembers[] = {
    property<[](O o) { return uint32_t(o.index()); }>("Index", kConst),
    property<[](O o) { return config(o).mt; }>("Address", kConst),
    property<[](O o) { return variant_name(config(o).variant); }>("Variant", kConst),
    property<[](O o) { return uint16_t(config(o).mux ? config(o).mux->addr7 : 0); }>("MuxAddress", kConst),
    property<[](O o) { return config(o).mux ? int32_t(config(o).mux->channel) : -1; }>("MuxChannel", kConst),
    property<[](O o) { return config(o).reversed; }>("Reversed", kConst),
    property<[](O o) { return o.driver().online(); }>("Online", kChange, kTick),
    property<&ThrusterObject::ordered_value>("OrderedValue", kChange, kTick),
    property<[](O o) { return o.driver().last_speed().value_or(kSpeedStop); }>("OrderedSpeed", kChange, kTick),
    property<[](O o) { return status<actual_speed>(o, kSpeedStop); }>("ActualSpeed", kChange, kTick),
    property<[](O o) { return status<current_amps>(o, 0.0); }>("Current", kChange, kTick),
    property<[](O o) { return status<temperature_c>(o, 0.0); }>("Temperature", kChange, kTick),
    property<[](O o) { return status<fault_names>(o, {}); }>("Faults", kChange, kTick),
    property<[](O o) { return status<firmware_revision>(o, 0); }>("FirmwareRevision", kChange, kTick),
    // One more order and status read every cycle: announced at 1 Hz.
    property<[](O o) { return counters(o).orders_sent; }>("OrdersSent", kChange, kCounterTick),
    property<[](O o) { return counters(o).order_failures; }>("OrderFailures", kChange, kTick),
    property<[](O o) { return counters(o).status_reads; }>("StatusReads", kChange, kCounterTick),
    property<[](O o) { return counters(o).nacks; }>("Nacks", kChange, kTick),
    property<[](O o) { return counters(o).timeouts; }>("Timeouts", kChange, kTick),
    property<[](O o) { return counters(o).bad_replies; }>("BadReplies", kChange, kTick),
    property<[](O o) { return error_text(o.driver()); }>("LastError", kChange, kTick),
};
constexpr auto kVtable = vtable(kMembers);

std::string path_of(size_t index) { return std::string(kRootPath) + "/thruster/" + std::to_string(index); }

} // namespace

ThrusterObject::ThrusterObject(sd_bus* bus, const ThrusterBus& thrusters, size_t index)
    : thrusters_(thrusters), index_(index), object_(bus, path_of(index), kThrusterIface, kMembers, kVtable, this) {}

} // namespace caracara::dbus
