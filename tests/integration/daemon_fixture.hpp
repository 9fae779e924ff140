// A running caracarad on the simulator of a SimFixture, and a client connection to it that
// stays open (the daemon zeroes the thrusters when its commanding client leaves).
#pragma once

#include "tests/integration/sim_fixture.hpp"

#include <string>
#include <vector>

namespace caracara::test {

class DaemonFixture {
public:
    // Writes `config` (TOML) and starts caracarad on the simulator's bus, or on `bus_address`
    // when given; waits until the name is owned and, if `wait_ready`, arms it (ClearKill of the
    // start kill) and waits until State is "ready".
    DaemonFixture(SimFixture& sim, const std::string& config, bool wait_ready = true,
                  const std::string& bus_address = {});
    ~DaemonFixture();

    sd_bus* bus() { return bus_.get(); }
    std::string vehicle_string(const char* prop, const char* path = "/org/caracara/Vehicle1",
                               const char* iface = "org.caracara.Vehicle1");
    uint64_t bus_u64(const char* prop);
    uint32_t bus_u32(const char* prop);
    // Calls a Vehicle1 method; returns "" or the D-Bus error name.
    std::string call(const char* method, const char* sig, ...);
    std::string set_thrust(const std::vector<int32_t>& v);
    bool wait_for(const std::function<bool()>& pred, int timeout_ms = 10000);

    Process daemon;

private:
    SimFixture& sim_;
    dbus::BusPtr bus_;
};

} // namespace caracara::test
