// dbus/VehicleService on a private dbus-daemon (ServiceRig): the composition itself. It owns
// org.caracara.Vehicle1, its ObjectManager lists every object (the vehicle, one per configured
// thruster, the Teensy, the bus; the vehicle's own object is the manager), and the daemon's events reach the bus as their signals.
#include "tests/catch.hpp"
#include "tests/unit/fakes/service_rig.hpp"

#include <set>
#include <string>

using namespace caracara;
using namespace caracara::test;

TEST_CASE("VehicleService: owns its name, and its ObjectManager lists every object with its interface") {
    ServiceRig s;
    s.rig().run_until_ready();
    // The bus's own answer (the dbus-daemon answers it; no need for the loop).
    sd_bus_error e = SD_BUS_ERROR_NULL;
    sd_bus_message* m = nullptr;
    REQUIRE(sd_bus_call_method(s.client(), "org.freedesktop.DBus", "/org/freedesktop/DBus", "org.freedesktop.DBus",
                               "NameHasOwner", &e, &m, "s", dbus::kBusName) >= 0);
    dbus::MessagePtr owned(m);
    int has = 0;
    REQUIRE(sd_bus_message_read(m, "b", &has) >= 0);
    CHECK(has);

    BusReply r = s.call(dbus::kRootPath, "org.freedesktop.DBus.ObjectManager", "GetManagedObjects", "");
    REQUIRE(r.ok());
    std::set<std::string> objects;
    m = r.reply.get();
    REQUIRE(sd_bus_message_enter_container(m, 'a', "{oa{sa{sv}}}") >= 0);
    while (sd_bus_message_enter_container(m, 'e', "oa{sa{sv}}") > 0) {
        const char* path = nullptr;
        REQUIRE(sd_bus_message_read(m, "o", &path) >= 0);
        REQUIRE(sd_bus_message_enter_container(m, 'a', "{sa{sv}}") >= 0);
        while (sd_bus_message_enter_container(m, 'e', "sa{sv}") > 0) {
            const char* iface = nullptr;
            REQUIRE(sd_bus_message_read(m, "s", &iface) >= 0);
            if (std::string(iface).rfind("org.freedesktop.", 0) != 0)
                objects.insert(std::string(path) + " " + iface);
            REQUIRE(sd_bus_message_skip(m, "a{sv}") >= 0);
            REQUIRE(sd_bus_message_exit_container(m) >= 0);
        }
        REQUIRE(sd_bus_message_exit_container(m) >= 0);
        REQUIRE(sd_bus_message_exit_container(m) >= 0);
    }
    // The manager's own object is not among the objects it manages (the D-Bus specification).
    std::set<std::string> expected{std::string(dbus::kTeensyPath) + " " + dbus::kTeensyIface,
                                   std::string(dbus::kBusPath) + " " + dbus::kBusIface};
    for (std::size_t i = 0; i < s.rig().config().thrusters.size(); ++i)
        expected.insert(std::string(dbus::kRootPath) + "/thruster/" + std::to_string(i) + " " + dbus::kThrusterIface);
    CHECK(objects == expected);
}

TEST_CASE("VehicleService: a failsafe raised is signalled once, one cleared is not") {
    ServiceRig s;
    s.rig().run_until_ready();
    int signals = 0;
    sd_bus_slot* slot = nullptr;
    REQUIRE(sd_bus_match_signal(s.client(), &slot, dbus::kBusName, dbus::kRootPath, dbus::kVehicleIface, "Failsafe",
                                [](sd_bus_message*, void* u, sd_bus_error*) {
                                    ++*static_cast<int*>(u);
                                    return 0;
                                },
                                &signals) >= 0);
    dbus::SlotPtr held(slot);
    ActiveFailsafe f;
    f.condition = FailsafeCondition::Overtemp;
    f.action = FailsafeAction::Exclude;
    f.thruster = 5;
    // As VehicleEvents tells its observer.
    s.service().failsafe(f, false);
    s.service().failsafe(f, true);
    REQUIRE(s.rig().run_until([&] { return signals > 0; }));
    s.rig().run_for(50);
    CHECK(signals == 1);
}
