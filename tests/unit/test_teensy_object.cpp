// dbus/TeensyObject (/org/caracara/Vehicle1/teensy) on a private dbus-daemon, serving the
// daemon's TeensyPort on the fakes of the device seam (ServiceRig), the Teensy not fitted: its
// properties say so, and each command is refused with the link's named error, moving nothing.
#include "core/status.hpp"
#include "tests/catch.hpp"
#include "tests/unit/fakes/service_rig.hpp"

#include <string>

using namespace caracara;
using namespace caracara::test;
using dbus::kTeensyIface;
using dbus::kTeensyPath;

TEST_CASE("TeensyObject: not fitted, it reads offline and idle, with no frames") {
    ServiceRig s;
    s.rig().run_until_ready();
    CHECK(s.basic<int>(kTeensyPath, kTeensyIface, "Online", 'b') == 0);
    CHECK(s.text(kTeensyPath, kTeensyIface, "Task") == "idle");
    CHECK(s.text(kTeensyPath, kTeensyIface, "LinkLoss") == std::string(name_of(s.rig().daemon().teensy().loss())));
    CHECK(s.basic<uint64_t>(kTeensyPath, kTeensyIface, "Frames", 't') == 0);
    CHECK(s.basic<uint64_t>(kTeensyPath, kTeensyIface, "OrientationReadNs", 't') == 0);
}

TEST_CASE("TeensyObject: each command refused with LinkError when the Teensy is not there; the vehicle unmoved") {
    ServiceRig s;
    s.rig().run_until_ready();
    const std::string link_error = "org.caracara.Vehicle1.Error.LinkError"; // the contract's name
    CHECK(s.call(kTeensyPath, kTeensyIface, "SetSpeed", "ii", 100, 100).error == link_error);
    CHECK(s.call(kTeensyPath, kTeensyIface, "Stop", "y", 50).error == link_error);
    CHECK(s.call(kTeensyPath, kTeensyIface, "SetServo", "yy", 1, 90).error == link_error);
    CHECK(s.call(kTeensyPath, kTeensyIface, "GetDistance", "y", 0).error == link_error);
    CHECK(s.call(kTeensyPath, kTeensyIface, "Turn", "d", 0.5).error == link_error);
    CHECK(s.call(kTeensyPath, kTeensyIface, "TurnTo", "d", 0.5).error == link_error);
    // Malformed arguments: sd-bus's InvalidArgs, before the Teensy port sees them.
    CHECK(s.call(kTeensyPath, kTeensyIface, "SetSpeed", "s", "fast").error == "org.freedesktop.DBus.Error.InvalidArgs");
    CHECK(s.text(kTeensyPath, kTeensyIface, "Task") == "idle");
    CHECK(s.text(dbus::kRootPath, dbus::kVehicleIface, "State") == "ready");
    // A command the Teensy cannot carry takes nothing: its caller did not become the commanding
    // client (whose leaving would zero another pilot's thrusters).
    CHECK(s.text(dbus::kRootPath, dbus::kVehicleIface, "Controller").empty());
}
