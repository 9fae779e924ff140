// One place every daemon object reports changes to: it forwards them to the presentation
// (a VehicleObserver, i.e. D-Bus) and, for state and bus changes, to systemd's STATUS= line.
// The receivers are attached once main has built them.
#pragma once

#include "daemon/vehicle_observer.hpp"

#include <cstdint>
#include <string>

namespace caracara {

class ServiceStatus;

class VehicleEvents {
public:
    void attach(VehicleObserver* observer) { observer_ = observer; }
    void attach(const ServiceStatus* status) { status_ = status; }

    void changed(uint32_t changes);
    void telemetry() {
        if (observer_)
            observer_->telemetry();
    }
    void bus_lost(const std::string& reason) {
        if (observer_)
            observer_->bus_lost(reason);
    }
    void bus_restored(uint32_t pulses, double milliseconds) {
        if (observer_)
            observer_->bus_restored(pulses, milliseconds);
    }

private:
    VehicleObserver* observer_ = nullptr;
    const ServiceStatus* status_ = nullptr;
};

} // namespace caracara
