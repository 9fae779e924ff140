#include "tests/integration/daemon_fixture.hpp"

#include <chrono>
#include <cstdarg>
#include <stdexcept>
#include <thread>

namespace caracara::test {

using namespace std::chrono_literals;

DaemonFixture::DaemonFixture(SimFixture& sim, const std::string& config, bool wait_ready,
                             const std::string& bus_address)
    : sim_(sim) {
    const std::string address = bus_address.empty() ? sim.bus_address() : bus_address;
    const std::string cfg = sim.write_file("caracarad.toml", config);
    daemon.start({bin("daemon/caracarad"), "--config", cfg, "--hardware=sim:" + sim.socket(), "--bus-address", address},
                 sim.dir() + "/caracarad.log");
    dbus::BusChoice choice{dbus::BusChoice::Kind::Address, address};
    if (dbus::open_bus(choice, "caracara-test-client", bus_) < 0)
        throw std::runtime_error("cannot connect to the private bus");
    const bool up = wait_for([&] {
        if (!daemon.running())
            throw std::runtime_error("caracarad exited at start; see " + sim.dir() + "/caracarad.log");
        return sd_bus_get_name_creds(bus_.get(), "org.caracara.Vehicle1", 0, nullptr) >= 0;
    });
    if (!up)
        throw std::runtime_error("caracarad did not come up; see " + sim.dir() + "/caracarad.log");
    if (!wait_ready)
        return;
    // Every start comes up killed (source "start"); a pilot's ClearKill arms it.
    if (vehicle_string("State") == "killed" && vehicle_string("KillSource") == "start")
        call("ClearKill", "");
    if (!wait_for([&] { return vehicle_string("State") == "ready"; }))
        throw std::runtime_error("caracarad did not become ready");
}

DaemonFixture::~DaemonFixture() {
    bus_.reset();
    daemon.stop();
}

bool DaemonFixture::wait_for(const std::function<bool()>& pred, int timeout_ms) {
    for (int waited = 0; waited < timeout_ms; waited += 5) {
        if (pred())
            return true;
        std::this_thread::sleep_for(5ms);
    }
    return pred();
}

std::string DaemonFixture::vehicle_string(const char* prop, const char* path, const char* iface) {
    sd_bus_error e = SD_BUS_ERROR_NULL;
    char* s = nullptr;
    if (sd_bus_get_property_string(bus_.get(), "org.caracara.Vehicle1", path, iface, prop, &e, &s) < 0) {
        sd_bus_error_free(&e);
        return "<error>";
    }
    std::string out = s;
    free(s);
    return out;
}

uint64_t DaemonFixture::bus_u64(const char* prop) {
    sd_bus_error e = SD_BUS_ERROR_NULL;
    uint64_t v = 0;
    sd_bus_get_property_trivial(bus_.get(), "org.caracara.Vehicle1", "/org/caracara/Vehicle1/bus",
                                "org.caracara.Vehicle1.Bus", prop, &e, 't', &v);
    sd_bus_error_free(&e);
    return v;
}

uint32_t DaemonFixture::bus_u32(const char* prop) {
    sd_bus_error e = SD_BUS_ERROR_NULL;
    uint32_t v = 0;
    sd_bus_get_property_trivial(bus_.get(), "org.caracara.Vehicle1", "/org/caracara/Vehicle1/bus",
                                "org.caracara.Vehicle1.Bus", prop, &e, 'u', &v);
    sd_bus_error_free(&e);
    return v;
}

namespace {
// Sends a prepared call and returns "" or the D-Bus error name.
std::string send_call(sd_bus* bus, sd_bus_message* m) {
    sd_bus_error e = SD_BUS_ERROR_NULL;
    sd_bus_message* reply = nullptr;
    int r = sd_bus_call(bus, m, 10'000'000, &e, &reply);
    sd_bus_message_unref(reply);
    std::string name = r < 0 ? (e.name ? e.name : "error") : "";
    sd_bus_error_free(&e);
    return name;
}
} // namespace

std::string DaemonFixture::call(const char* method, const char* sig, ...) {
    sd_bus_message* m = nullptr;
    sd_bus_message_new_method_call(bus_.get(), &m, "org.caracara.Vehicle1", "/org/caracara/Vehicle1",
                                   "org.caracara.Vehicle1", method);
    dbus::MessagePtr guard(m);
    va_list ap;
    va_start(ap, sig);
    sd_bus_message_appendv(m, sig, ap);
    va_end(ap);
    return send_call(bus_.get(), m);
}

std::string DaemonFixture::set_thrust(const std::vector<int32_t>& v) {
    sd_bus_message* m = nullptr;
    sd_bus_message_new_method_call(bus_.get(), &m, "org.caracara.Vehicle1", "/org/caracara/Vehicle1",
                                   "org.caracara.Vehicle1", "SetThrust");
    dbus::MessagePtr guard(m);
    sd_bus_message_append_array(m, 'i', v.data(), v.size() * sizeof(int32_t));
    return send_call(bus_.get(), m);
}

} // namespace caracara::test
