// dbus/ThrusterObject (/org/caracara/Vehicle1/thruster/N) on a private dbus-daemon, serving the
// daemon's ThrusterBus on the fakes of the device seam (ServiceRig): one object per configured
// thruster, each property read from its own driver, and a thruster that stops answering shows
// it on its own object only.
#include "core/status.hpp"
#include "tests/catch.hpp"
#include "tests/unit/fakes/service_rig.hpp"

#include <cerrno>
#include <string>
#include <vector>

using namespace caracara;
using namespace caracara::test;
using dbus::kThrusterIface;

namespace {

std::string path(std::size_t i) { return std::string(dbus::kRootPath) + "/thruster/" + std::to_string(i); }

template <typename T>
T basic(ServiceRig& s, std::size_t i, const char* property, char type) {
    return s.basic<T>(path(i).c_str(), kThrusterIface, property, type);
}

} // namespace

TEST_CASE("ThrusterObject: one object per configured thruster, its settings as configured") {
    ServiceRig s;
    s.rig().run_until_ready();
    const auto& thrusters = s.rig().config().thrusters;
    REQUIRE(thrusters.size() == kMotorCount);
    for (std::size_t i = 0; i < thrusters.size(); ++i) {
        INFO("thruster " << i);
        CHECK(basic<uint32_t>(s, i, "Index", 'u') == i);
        CHECK(basic<uint8_t>(s, i, "Address", 'y') == thrusters[i].mt);
        CHECK(s.text(path(i).c_str(), kThrusterIface, "Variant") == std::string(variant_name(thrusters[i].variant)));
        CHECK(basic<int>(s, i, "Reversed", 'b') == int(thrusters[i].reversed));
        CHECK(basic<int32_t>(s, i, "MuxChannel", 'i') == (thrusters[i].mux ? int32_t(thrusters[i].mux->channel) : -1));
        CHECK(basic<int>(s, i, "Online", 'b') == 1);
        CHECK(s.text(path(i).c_str(), kThrusterIface, "LastError").empty());
        CHECK(basic<uint64_t>(s, i, "OrdersSent", 't') >= 1);
    }
    // No object past the last thruster.
    BusReply r = s.call(path(thrusters.size()).c_str(), "org.freedesktop.DBus.Properties", "Get", "ss", kThrusterIface,
                        "Index");
    CHECK_FALSE(r.ok());
}

TEST_CASE("ThrusterObject: OrderedValue is each thruster's own order") {
    ServiceRig s;
    s.rig().run_until_ready();
    const std::vector<int32_t>& values = kThrust;
    REQUIRE(s.set_thrust(values).ok());
    // What the bus ordered, once the loop handed it over.
    const ThrusterBus& bus = s.rig().daemon().bus();
    REQUIRE(s.rig().run_until([&] {
        for (std::size_t i = 0; i < values.size(); ++i)
            if (bus.ordered_value(i) != values[i])
                return false;
        return true;
    }));
    for (std::size_t i = 0; i < values.size(); ++i) {
        INFO("thruster " << i);
        CHECK(basic<int32_t>(s, i, "OrderedValue", 'i') == values[i]);
    }
}

TEST_CASE("ThrusterObject: a thruster that stops answering is offline with its error, the others not") {
    ServiceRig s;
    s.rig().run_until_ready();
    const uint64_t before = basic<uint64_t>(s, 3, "Timeouts", 't') + basic<uint64_t>(s, 3, "Nacks", 't') +
                            basic<uint64_t>(s, 3, "OrderFailures", 't');
    s.rig().wire().fail(3, EIO);
    REQUIRE(s.rig().run_until([&] { return !s.rig().daemon().bus().thruster(3).online(); }));
    CHECK(basic<int>(s, 3, "Online", 'b') == 0);
    CHECK_FALSE(s.text(path(3).c_str(), kThrusterIface, "LastError").empty());
    CHECK(basic<uint64_t>(s, 3, "OrderFailures", 't') > 0);
    CHECK(basic<uint64_t>(s, 3, "Timeouts", 't') + basic<uint64_t>(s, 3, "Nacks", 't') +
              basic<uint64_t>(s, 3, "OrderFailures", 't') > before);
    for (std::size_t i : {0u, 2u, 4u}) {
        INFO("thruster " << i);
        CHECK(basic<int>(s, i, "Online", 'b') == 1);
        CHECK(basic<uint64_t>(s, i, "OrderFailures", 't') == 0);
    }
}
