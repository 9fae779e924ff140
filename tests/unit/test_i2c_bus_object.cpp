// dbus/I2cBusObject (/org/caracara/Vehicle1/bus) on a private dbus-daemon, serving the daemon's
// BusMonitor on the fakes of the device seam (ServiceRig): its properties read the monitor,
// and BusLost / BusRestored reach a client with their arguments.
#include "tests/catch.hpp"
#include "tests/unit/fakes/service_rig.hpp"

#include <string>

using namespace caracara;
using namespace caracara::test;
using dbus::kBusIface;
using dbus::kBusPath;

TEST_CASE("I2cBusObject: the properties read the bus monitor") {
    ServiceRig s;
    s.rig().run_until_ready();
    const BusMonitor& monitor = s.rig().daemon().bus().monitor();
    CHECK(s.text(kBusPath, kBusIface, "Device") == s.rig().config().i2c.device);
    CHECK(s.text(kBusPath, kBusIface, "State") == "ok");
    CHECK(s.basic<uint64_t>(kBusPath, kBusIface, "Errors", 't') == 0);
    CHECK(s.basic<uint64_t>(kBusPath, kBusIface, "Recoveries", 't') == 0);
    CHECK(s.text(kBusPath, kBusIface, "LastError").empty());
    // The transactions counted so far, read when asked (they go on at every cycle).
    const uint64_t transactions = s.basic<uint64_t>(kBusPath, kBusIface, "Transactions", 't');
    CHECK(transactions > 0);
    CHECK(transactions <= monitor.telemetry().transactions);
}

TEST_CASE("I2cBusObject: BusLost and BusRestored carry their reason, pulses and time") {
    ServiceRig s;
    s.rig().run_until_ready();
    struct Seen {
        std::string lost;
        uint32_t pulses = 0;
        double ms = 0;
        bool restored = false;
    } seen;
    auto on_lost = [](sd_bus_message* m, void* userdata, sd_bus_error*) {
        const char* reason = nullptr;
        if (sd_bus_message_read(m, "s", &reason) >= 0)
            static_cast<Seen*>(userdata)->lost = reason;
        return 0;
    };
    auto on_restored = [](sd_bus_message* m, void* userdata, sd_bus_error*) {
        auto* out = static_cast<Seen*>(userdata);
        out->restored = sd_bus_message_read(m, "ud", &out->pulses, &out->ms) >= 0;
        return 0;
    };
    sd_bus_slot *a = nullptr, *b = nullptr;
    REQUIRE(sd_bus_match_signal(s.client(), &a, dbus::kBusName, kBusPath, kBusIface, "BusLost", on_lost, &seen) >= 0);
    REQUIRE(sd_bus_match_signal(s.client(), &b, dbus::kBusName, kBusPath, kBusIface, "BusRestored", on_restored, &seen) >= 0);
    dbus::SlotPtr held_a(a), held_b(b);
    // As the daemon's VehicleEvents tell the service (VehicleObserver).
    s.service().bus_lost("SDA held low");
    s.service().bus_restored(9, 12.5);
    REQUIRE(s.rig().run_until([&] { return seen.restored && !seen.lost.empty(); }));
    CHECK(seen.lost == "SDA held low");
    CHECK(seen.pulses == 9);
    CHECK(seen.ms == 12.5);
}
