// dbus/ClientTracker on a private dbus-daemon (ServiceRig): a client that leaves the bus is told
// to the Vehicle by its unique name (NameOwnerChanged), so the controlling client's command
// stops at once (its zeros on the fake wire), and one that never commanded changes nothing.
#include "tests/catch.hpp"
#include "tests/unit/fakes/service_rig.hpp"

#include <string>
#include <vector>

using namespace caracara;
using namespace caracara::test;
using dbus::kRootPath;
using dbus::kVehicleIface;

namespace {

std::string controller(ServiceRig& s) { return s.text(kRootPath, kVehicleIface, "Controller"); }

} // namespace

TEST_CASE("ClientTracker: the controlling client leaving the bus stops its command; another leaving does not") {
    // The command timeout far away: only the client's leaving can stop its command here.
    ServiceRig s("loop_rate_hz = 50\ncommand_timeout_ms = 60000\n");
    s.rig().run_until_ready();
    dbus::BusPtr bystander = s.connect("bystander");
    REQUIRE(s.set_thrust(kThrust).ok());
    REQUIRE(s.rig().run_until([&] { return s.each_ordered(kThrust); }));
    bystander.reset(); // a client that never commanded
    s.rig().run_for(100);
    CHECK(controller(s) == s.client_name());
    CHECK(s.ints(kRootPath, kVehicleIface, "MotorValues") == kThrust);

    dbus::BusPtr pilot = s.connect("pilot");
    std::vector<int32_t> other = kThrust;
    other[0] = 2500;
    REQUIRE(s.set_thrust(other, pilot.get()).ok());
    const char* pilot_name = nullptr;
    REQUIRE(sd_bus_get_unique_name(pilot.get(), &pilot_name) >= 0);
    CHECK(controller(s) == pilot_name);
    s.rig().wire().clear();
    pilot.reset();
    CHECK(s.rig().run_until([&] { return s.each_ordered(kZeros); }));
    CHECK(controller(s).empty());
    CHECK(s.ints(kRootPath, kVehicleIface, "MotorValues") == kZeros);
}
