// One place every daemon object reports changes to: it forwards them to systemd's STATUS=
// line (ServiceStatus), to the dive recorder and to the presentation (D-Bus), each a
// VehicleObserver, in that order. The receivers are attached once main has built them.
#pragma once

#include "daemon/interfaces/vehicle_observer.hpp"

#include <cstdint>
#include <functional>
#include <string>

namespace caracara {

class VehicleEvents {
public:
    void attach(VehicleObserver* observer) { observer_ = observer; }
    void attach_status(VehicleObserver* status) { status_ = status; }
    void attach_recorder(VehicleObserver* recorder) { recorder_ = recorder; }
    // Who is calling, while a D-Bus method runs (the presentation layer knows; "" otherwise):
    // the recorder writes it beside each state change.
    void set_caller_source(std::function<std::string()> source) { caller_ = std::move(source); }
    std::string caller() const { return caller_ ? caller_() : std::string(); }

    void changed(uint32_t changes);
    void telemetry() {
        if (observer_)
            observer_->telemetry();
    }
    void cycle(uint64_t now_ns) {
        if (recorder_)
            recorder_->cycle(now_ns);
    }
    void orders_in_flight(bool in_flight) {
        if (observer_)
            observer_->orders_in_flight(in_flight);
    }
    void bus_lost(const std::string& reason) {
        for (VehicleObserver* o : {recorder_, observer_})
            if (o)
                o->bus_lost(reason);
    }
    void bus_restored(uint32_t pulses, double milliseconds) {
        for (VehicleObserver* o : {recorder_, observer_})
            if (o)
                o->bus_restored(pulses, milliseconds);
    }

    void motor_test(int32_t thruster, int32_t value) {
        if (recorder_)
            recorder_->motor_test(thruster, value);
    }

    void failsafe(const ActiveFailsafe& f, bool raised) {
        for (VehicleObserver* o : {recorder_, observer_})
            if (o)
                o->failsafe(f, raised);
    }

private:
    VehicleObserver* observer_ = nullptr;
    VehicleObserver* recorder_ = nullptr;
    VehicleObserver* status_ = nullptr;
    std::function<std::string()> caller_;
};

} // namespace caracara
