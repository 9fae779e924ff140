#include "sim/inspect_simulator.hpp"

#include "core/clock.hpp"
#include "drivers/sdbus/property.hpp"
#include "sim/inspect_reply.hpp"
#include "sim/simulator_parts.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace caracara::sim {

namespace {

using dbus::kConst;
using dbus::kUnpriv; // who may call what is the bus policy's job (systemd/org.caracara.Simulator1.conf)
using dbus::member;
using dbus::property;

SimVehicle& vehicle(void* userdata) { return static_cast<SimulatorParts*>(userdata)->vehicle; }

int m_set_kill_switch(sd_bus_message* m, void* userdata, sd_bus_error*) {
    int on = 0;
    if (int r = sd_bus_message_read(m, "b", &on); r < 0)
        return r;
    vehicle(userdata).gpio().set_kill_switch(on, monotonic_ns());
    return sd_bus_reply_method_return(m, "");
}

int m_hang_bus(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    uint32_t pulses = 0;
    if (int r = sd_bus_message_read(m, "u", &pulses); r < 0)
        return r;
    if (pulses < 1 || pulses > 9)
        return sd_bus_error_setf(err, kInspectInvalid, "a slave holds SDA for 1..9 clock pulses, got %u", pulses);
    vehicle(userdata).i2c().hang_sda(pulses);
    return sd_bus_reply_method_return(m, "");
}

int m_vanish(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    const char* device = nullptr;
    uint32_t ms = 0;
    if (int r = sd_bus_message_read(m, "su", &device, &ms); r < 0)
        return r;
    const std::string d = device;
    if (d != "i2c" && d != "spi")
        return sd_bus_error_setf(err, kInspectInvalid, "the device to vanish is 'i2c' or 'spi', got '%s'", device);
    vehicle(userdata).vanish(d == "i2c" ? SimVehicle::NodeKind::I2c : SimVehicle::NodeKind::Spi, ms, monotonic_ns());
    return sd_bus_reply_method_return(m, "");
}

// SetLinePresent(s line, b present): one of the safety lines (KILL_SWITCH, KILL_OUT, POWER_OFF,
// the chip's names) taken away or brought back (GpioModel::set_present).
int m_set_line_present(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    const char* name = nullptr;
    int present = 0;
    if (int r = sd_bus_message_read(m, "sb", &name, &present); r < 0)
        return r;
    GpioModel& g = vehicle(userdata).gpio();
    const int line = g.find(GpioModel::kChip, name, -1);
    const std::string n = name;
    if (line < 0 || (n != "KILL_SWITCH" && n != "KILL_OUT" && n != "POWER_OFF"))
        return sd_bus_error_setf(err, kInspectInvalid, "the line is KILL_SWITCH, KILL_OUT or POWER_OFF, got '%s'", name);
    g.set_present(line, present, monotonic_ns());
    return sd_bus_reply_method_return(m, "");
}

int m_hold_scl(sd_bus_message* m, void* userdata, sd_bus_error*) {
    vehicle(userdata).i2c().hang_scl();
    return sd_bus_reply_method_return(m, "");
}

int m_release_bus(sd_bus_message* m, void* userdata, sd_bus_error*) {
    vehicle(userdata).i2c().clear_hang();
    return sd_bus_reply_method_return(m, "");
}

// GetWireLog(t since) -> (t next, a(tttsqbayays)): index, time_ns, transaction, bus, addr,
// read, data, miso, result (the kinds of entry are in wire_log.hpp). bus "i2c" and "spi" are
// transactions; "i2c-lines" are recovery line events; "gpio" is a GPIO line level change:
// addr = the line offset (KillSwitchLine for the kill switch), data = {new level on the wire},
// result "edge", time_ns = the moment of the change (for the kill switch, the moment
// SetKillSwitch changed it, which is when caracarad's edge event can fire).
// A reply is one page: the entries from `since` up to kMaxReplyBytes of message, `next` the
// index to ask for next (the log's end once it is all read). The bus drops a sender whose
// message exceeds its limit (dbus-daemon's max_message_size, 32 MiB unless configured), so an
// unbounded reply of a large log (the soak's [sim] wire_log_entries = 2000000) took the
// simulator off the bus. The default log (200000 entries, about 14 MB) fits in one page.
// GetWireLogPage(t since, u max_entries) is the same with a smaller page of the caller's choice
// (a reader that must not stall on one large reply).
constexpr size_t kMaxReplyBytes = 16u << 20;

// What entry `e` takes in the message, with room for the alignment (at least 8 bytes each).
size_t marshalled_size(const WireEntry& e) {
    return 64 + e.bus.size() + e.data.size() + e.miso.size() + e.result.size();
}

int wire_log_page(sd_bus_message* m, void* userdata, uint64_t since, size_t max_entries) {
    return reply_with(m, [&](sd_bus_message* reply) {
        const WireLog& log = vehicle(userdata).log();
        std::vector<const WireEntry*> page = log.since(since, max_entries);
        size_t bytes = 0, n = 0;
        while (n < page.size() && (bytes += marshalled_size(*page[n])) <= kMaxReplyBytes)
            ++n;
        page.resize(n);
        // Indexes are consecutive: after the last entry of the log this is the log's end.
        const uint64_t next = page.empty() ? log.next_index() : page.back()->index + 1;
        int r = sd_bus_message_append(reply, "t", next);
        if (r >= 0)
            r = sd_bus_message_open_container(reply, 'a', "(tttsqbayays)");
        for (const WireEntry* e : page) {
            if (r >= 0) r = sd_bus_message_open_container(reply, 'r', "tttsqbayays");
            if (r >= 0) r = sd_bus_message_append(reply, "tttsqb", e->index, e->time_ns, e->transaction, e->bus.c_str(), e->addr, static_cast<int>(e->read));
            if (r >= 0) r = sd_bus_message_append_array(reply, 'y', e->data.data(), e->data.size());
            if (r >= 0) r = sd_bus_message_append_array(reply, 'y', e->miso.data(), e->miso.size());
            if (r >= 0) r = sd_bus_message_append(reply, "s", e->result.c_str());
            if (r >= 0) r = sd_bus_message_close_container(reply);
        }
        return r < 0 ? r : sd_bus_message_close_container(reply);
    });
}

int m_wire_log(sd_bus_message* m, void* userdata, sd_bus_error*) {
    uint64_t since = 0;
    if (int r = sd_bus_message_read(m, "t", &since); r < 0)
        return r;
    return wire_log_page(m, userdata, since, SIZE_MAX);
}

int m_wire_log_page(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    uint64_t since = 0;
    uint32_t max_entries = 0;
    if (int r = sd_bus_message_read(m, "tu", &since, &max_entries); r < 0)
        return r;
    if (max_entries < 1)
        return sd_bus_error_setf(err, kInspectInvalid, "a page holds at least 1 entry, got %u", max_entries);
    return wire_log_page(m, userdata, since, max_entries);
}

int m_clear_log(sd_bus_message* m, void* userdata, sd_bus_error*) {
    vehicle(userdata).log().clear();
    return sd_bus_reply_method_return(m, "");
}

int m_set_realistic(sd_bus_message* m, void* userdata, sd_bus_error*) {
    int on = 0;
    if (int r = sd_bus_message_read(m, "b", &on); r < 0)
        return r;
    vehicle(userdata).set_realistic_timing(on);
    return sd_bus_reply_method_return(m, "");
}

int m_set_clock(sd_bus_message* m, void* userdata, sd_bus_error* err) {
    uint32_t hz = 0;
    if (int r = sd_bus_message_read(m, "u", &hz); r < 0)
        return r;
    if (hz < 1000 || hz > 3400000)
        return sd_bus_error_setf(err, kInspectInvalid, "clock must be 1000..3400000 Hz, got %u", hz);
    vehicle(userdata).i2c().set_clock_hz(hz);
    return sd_bus_reply_method_return(m, "");
}

using I = SimulatorParts&;
I2cBusModel& i2c(I i) { return i.vehicle.i2c(); }
GpioModel& gpio(I i) { return i.vehicle.gpio(); }

constexpr dbus::Member kMembers[] = {
    property<[](I i) { return i2c(i).clock_hz(); }>("ClockHz"),
    property<[](I i) { return i.vehicle.realistic_timing(); }>("RealisticTiming"),
    property<[](I i) { return i2c(i).transactions(); }>("Transactions"),
    property<[](I i) { return i2c(i).wire_time_ns(); }>("WireTimeNs"),
    property<[](I i) { return uint32_t(i.vehicle.thrusters().size()); }>("ThrusterCount", kConst),
    property<[](I i) { return i.server.bad_requests(); }>("BadRequests"),
    property<[](I i) { return uint32_t(i.server.clients()); }>("Clients"),
    member(SD_BUS_METHOD_WITH_ARGS("GetWireLog", SD_BUS_ARGS("t", since), SD_BUS_RESULT("t", next, "a(tttsqbayays)", entries),
                                   m_wire_log, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("GetWireLogPage", SD_BUS_ARGS("t", since, "u", max_entries),
                                   SD_BUS_RESULT("t", next, "a(tttsqbayays)", entries), m_wire_log_page, kUnpriv)),
    member(SD_BUS_METHOD("ClearWireLog", "", "", m_clear_log, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("SetRealisticTiming", SD_BUS_ARGS("b", enabled), SD_BUS_NO_RESULT, m_set_realistic, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("SetClock", SD_BUS_ARGS("u", hz), SD_BUS_NO_RESULT, m_set_clock, kUnpriv)),
    property<[](I i) { return gpio(i).kill_switch_engaged(); }>("KillSwitch"),
    property<[](I) { return GpioModel::kKillSwitch; }>("KillSwitchLine", kConst),
    property<[](I) { return GpioModel::kKillOut; }>("KillOutputLine", kConst),
    property<[](I i) { return gpio(i).kill_switch_active_low(); }>("KillSwitchActiveLow", kConst),
    property<[](I i) { return gpio(i).level(GpioModel::kKillOut); }>("KillOutput"),
    property<[](I i) { return gpio(i).level(GpioModel::kPowerOff); }>("PowerOffOutput"),
    property<[](I i) { return gpio(i).level(GpioModel::kScl); }>("Scl"),
    property<[](I i) { return gpio(i).level(GpioModel::kSda); }>("Sda"),
    property<[](I i) { return i2c(i).i2c_function(); }>("I2cFunction"),
    property<[](I i) { return i.vehicle.i2c_timeout; }>("I2cTimeout"),
    property<[](I i) { return i.vehicle.i2c_retries; }>("I2cRetries"),
    property<[](I i) { return i.vehicle.driver_bound(); }>("DriverBound"),
    property<[](I i) { return i.vehicle.unbinds(); }>("Unbinds"),
    property<[](I i) { return i.vehicle.binds(); }>("Binds"),
    property<[](I i) { return name_of(i2c(i).hang()); }>("BusHang"),
    property<[](I i) { return i2c(i).hang_pulses_seen(); }>("HangPulsesSeen"),
    property<[](I i) { return i2c(i).hang_pulses_needed(); }>("HangPulsesNeeded"),
    property<[](I i) { return gpio(i).scl_pulses(); }>("SclPulses"),
    property<[](I i) { return gpio(i).stops(); }>("Stops"),
    property<[](I i) { return gpio(i).min_scl_period_ns(); }>("MinSclPeriodNs"),
    member(SD_BUS_METHOD_WITH_ARGS("SetKillSwitch", SD_BUS_ARGS("b", engaged), SD_BUS_NO_RESULT, m_set_kill_switch, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("Vanish", SD_BUS_ARGS("s", device, "u", ms), SD_BUS_NO_RESULT, m_vanish, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("SetLinePresent", SD_BUS_ARGS("s", line, "b", present), SD_BUS_NO_RESULT,
                                   m_set_line_present, kUnpriv)),
    member(SD_BUS_METHOD_WITH_ARGS("HangBus", SD_BUS_ARGS("u", pulses), SD_BUS_NO_RESULT, m_hang_bus, kUnpriv)),
    member(SD_BUS_METHOD("HoldScl", "", "", m_hold_scl, kUnpriv)),
    member(SD_BUS_METHOD("ReleaseBus", "", "", m_release_bus, kUnpriv)),
};
constexpr auto kVtable = dbus::vtable(kMembers);

} // namespace

const sd_bus_vtable* simulator_inspection() { return kVtable.data(); }

} // namespace caracara::sim
