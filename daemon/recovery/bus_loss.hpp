// Declaring the I2C bus lost: the thrusters cannot be reached, so the vehicle is killed
// (source bus) and stays so until the bus is back. A lockup under recovery that outlasts the
// command timeout is a lost bus too: it has left the thrusters unreachable for longer than any
// command may stand. Owns that timer; when to recover is BusRecovery's.
#pragma once

#include "core/config.hpp"
#include "daemon/bus/thruster_bus.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "daemon/vehicle/vehicle.hpp"
#include "drivers/platform/event_loop.hpp"

#include <cstdint>
#include <string>

namespace caracara {

class BusLoss {
public:
    BusLoss(sd_event* event, const ControlSettings& control, ThrusterBus& bus, Vehicle& vehicle, VehicleEvents& events)
        : event_(event), control_(control), bus_(bus), vehicle_(vehicle), events_(events) {}

    // A lockup is being recovered: lost if the bus is still recovering after the command timeout.
    void watch();
    // The bus is back: the command timeout no longer runs.
    void recovered();
    // Bus state Lost, the vehicle killed; nothing if the bus already is.
    void declare(const std::string& why);
    void stop() { timer_.reset(); }

private:
    static int on_timer(sd_event_source*, uint64_t usec, void* userdata);

    sd_event* event_;
    const ControlSettings& control_;
    ThrusterBus& bus_;
    Vehicle& vehicle_;
    VehicleEvents& events_;
    SourcePtr timer_;
};

} // namespace caracara
