// The control loop's InputProbe over an sd-bus connection.
#pragma once

#include "daemon/interfaces/input_probe.hpp"

#include <systemd/sd-bus.h>

namespace caracara::dbus {

class BusInputProbe final : public InputProbe {
public:
    explicit BusInputProbe(sd_bus* bus) : bus_(bus) {}
    bool queued() const override {
        uint64_t n = 0;
        return sd_bus_get_n_queued_read(bus_, &n) >= 0 && n > 0;
    }
    int fd() const override { return sd_bus_get_fd(bus_); }

private:
    sd_bus* bus_;
};

} // namespace caracara::dbus
