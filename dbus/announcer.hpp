// PropertiesChanged coalesced: every change flag and telemetry tick that comes in before the
// event loop gets down to kAnnouncePriority goes out in one flush, after the reply and the
// orders of the change (see kAnnouncePriority). Steady counters go out at every fifth tick.
#pragma once

#include "daemon/control/control_loop.hpp" // kAnnouncePriority
#include "drivers/sdbus/sdbus.hpp"

#include <cstdint>
#include <functional>

namespace caracara::dbus {

// Announcement flags beyond VehicleChange's: a telemetry tick (5 Hz), and every fifth one
// (1 Hz) for counters that move at every cycle.
inline constexpr uint32_t kTelemetryTick = 1u << 16;
inline constexpr uint32_t kCounterTick = 1u << 17;

class Announcer {
public:
    using Flush = std::function<void(uint32_t changes)>;
    Announcer(sd_bus* bus, Flush flush) : bus_(bus), flush_(std::move(flush)) {}
    // VehicleChange flags and/or kTelemetryTick.
    void request(uint32_t changes);
    // While a command's orders are on their way to the wire, what announces the command (its
    // motor values, its controller) and telemetry wait for them: the signal then says what the
    // wire carries, and is not built while the command's reply, the bus worker and the devices
    // want the CPU. Everything else (a kill's state, a fault) goes at once, and takes what waits.
    void hold(bool held);

private:
    static int on_flush(sd_event_source*, void* userdata);

    sd_bus* bus_;
    Flush flush_;
    uint32_t pending_ = 0;
    bool held_ = false;
    uint64_t ticks_ = 0;
    SourcePtr source_;
};

} // namespace caracara::dbus
