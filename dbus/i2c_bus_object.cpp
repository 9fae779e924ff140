#include "dbus/i2c_bus_object.hpp"

#include "dbus/announcer.hpp"
#include "dbus/vehicle_names.hpp"

namespace caracara::dbus {

namespace {

using C = const BusMonitor&;
// Announced at telemetry ticks and as soon as the controller reports a bus event.
constexpr uint32_t kNow = kTelemetryTick | kChangeBus;

constexpr Member kMembers[] = {
    property<[](C c) -> const auto& { return c.device(); }>("Device", kConst),
    property<[](C c) { return bus_state_name(c.telemetry().state); }>("State", kChange, kNow),
    property<[](C c) { return c.telemetry().transactions; }>("Transactions", kChange, kCounterTick), // every cycle: 1 Hz
    property<[](C c) { return c.telemetry().errors; }>("Errors", kChange, kNow),
    property<[](C c) -> const auto& { return c.telemetry().last_error; }>("LastError", kChange, kNow),
    property<[](C c) { return c.telemetry().recoveries; }>("Recoveries", kChange, kNow),
    property<[](C c) { return c.telemetry().recovery_failures; }>("RecoveryFailures", kChange, kNow),
    property<[](C c) { return c.telemetry().last_pulses; }>("LastPulses", kChange, kNow),
    property<[](C c) { return c.telemetry().last_recovery_ms; }>("LastRecoveryMs", kChange, kNow),
    property<[](C c) -> const auto& { return c.telemetry().last_recovery_error; }>("LastRecoveryError", kChange, kNow),
    member(SD_BUS_SIGNAL_WITH_ARGS("BusLost", SD_BUS_ARGS("s", reason), 0)),
    member(SD_BUS_SIGNAL_WITH_ARGS("BusRestored", SD_BUS_ARGS("u", pulses, "d", milliseconds), 0)),
};
constexpr auto kVtable = vtable(kMembers);

} // namespace

I2cBusObject::I2cBusObject(sd_bus* bus, BusMonitor& monitor)
    : object_(bus, kBusPath, kBusIface, kMembers, kVtable, &monitor) {}

void I2cBusObject::emit_lost(const std::string& reason) {
    sd_bus_emit_signal(object_.bus(), object_.path().c_str(), object_.iface(), "BusLost", "s", reason.c_str());
}

void I2cBusObject::emit_restored(uint32_t pulses, double milliseconds) {
    sd_bus_emit_signal(object_.bus(), object_.path().c_str(), object_.iface(), "BusRestored", "ud", pulses, milliseconds);
}

} // namespace caracara::dbus
