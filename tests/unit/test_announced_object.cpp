// dbus/AnnouncedObject, as a client sees its PropertiesChanged on a private dbus-daemon
// (ServiceRig): an object announced "Changed" (a thruster) carries a member only when its value
// moved since it was last announced, never a constant one; one announced "Always" (the vehicle)
// carries every member of each change it is told of, even when the values are the same again.
#include "tests/catch.hpp"
#include "tests/unit/fakes/service_rig.hpp"

#include <algorithm>
#include <string>
#include <vector>

using namespace caracara;
using namespace caracara::test;

namespace {

// Each PropertiesChanged on one path: the names it carried, and OrderedValue / MotorValues[0]
// when it carried them.
struct Announced {
    std::vector<std::vector<std::string>> names;
    std::vector<int32_t> values;
};

int on_changed(sd_bus_message* m, void* userdata, sd_bus_error*) {
    auto* out = static_cast<Announced*>(userdata);
    const char* iface = nullptr;
    if (sd_bus_message_read(m, "s", &iface) < 0 || sd_bus_message_enter_container(m, 'a', "{sv}") < 0)
        return 0;
    std::vector<std::string> names;
    while (sd_bus_message_enter_container(m, 'e', "sv") > 0) {
        const char* name = nullptr;
        sd_bus_message_read(m, "s", &name);
        names.emplace_back(name);
        if (names.back() == "OrderedValue" && sd_bus_message_enter_container(m, 'v', "i") > 0) {
            int32_t v = 0;
            sd_bus_message_read(m, "i", &v);
            out->values.push_back(v);
            sd_bus_message_exit_container(m);
        } else if (names.back() == "MotorValues" && sd_bus_message_enter_container(m, 'v', "ai") > 0) {
            const void* p = nullptr;
            size_t n = 0;
            sd_bus_message_read_array(m, 'i', &p, &n);
            out->values.push_back(n ? *static_cast<const int32_t*>(p) : 0);
            sd_bus_message_exit_container(m);
        } else {
            sd_bus_message_skip(m, "v");
        }
        sd_bus_message_exit_container(m);
    }
    out->names.push_back(std::move(names));
    return 0;
}

bool carried(const Announced& a, const std::string& name) {
    for (const auto& names : a.names)
        for (const auto& n : names)
            if (n == name)
                return true;
    return false;
}

dbus::SlotPtr watch(ServiceRig& s, const std::string& path, Announced& into) {
    sd_bus_slot* slot = nullptr;
    if (sd_bus_match_signal(s.client(), &slot, dbus::kBusName, path.c_str(), "org.freedesktop.DBus.Properties",
                            "PropertiesChanged", on_changed, &into) < 0)
        throw std::runtime_error("cannot watch " + path);
    return dbus::SlotPtr(slot);
}

// The command timeout far: nothing but the test's commands moves the values.
const std::string kControl = "loop_rate_hz = 50\ncommand_timeout_ms = 60000\n";

} // namespace

TEST_CASE("AnnouncedObject (Changed): a thruster's member goes out when its value moved, once; a constant never") {
    ServiceRig s(kControl);
    s.rig().run_until_ready();
    const std::string path = std::string(dbus::kRootPath) + "/thruster/0";
    Announced a;
    dbus::SlotPtr held = watch(s, path, a);
    // Settled: online, and its first order's value on the wire (a slow build takes longer).
    const ThrusterBus& bus = s.rig().daemon().bus();
    REQUIRE(s.rig().run_until([&] { return bus.thruster(0).online() && bus.ordered_value(0) == 0; }));
    REQUIRE(s.set_thrust(kThrust).ok());
    // The tick after the order carries it (and whatever else moved since the last one).
    CHECK(s.rig().run_until([&] { return !a.values.empty() && a.values.back() == kThrust[0]; }));
    // Unchanged since, over three more telemetry ticks: no OrderedValue again.
    a = {};
    s.rig().run_for(600);
    CHECK_FALSE(carried(a, "OrderedValue"));
    CHECK_FALSE(carried(a, "Online"));
    for (const char* constant : {"Index", "Address", "Variant", "MuxAddress", "MuxChannel", "Reversed"})
        CHECK_FALSE(carried(a, constant));
}

TEST_CASE("AnnouncedObject (Always): each change announces its members, the same values again too") {
    ServiceRig s(kControl);
    s.rig().run_until_ready();
    Announced a;
    dbus::SlotPtr held = watch(s, dbus::kRootPath, a);
    // A command's change: every member of it, BudgetLimit and Saturated unchanged or not.
    REQUIRE(s.set_thrust(kThrust).ok());
    REQUIRE(s.rig().run_until([&] { return carried(a, "MotorValues"); }));
    for (const char* member : {"MotorValues", "RequestedValues", "BudgetLimit", "Saturated"})
        CHECK(carried(a, member));
    // The profile's change told twice, its values the same: announced twice.
    // (A telemetry tick may go in the same signal: only the profile's signals are counted.)
    a = {};
    const auto profile_signals = [&] {
        std::size_t n = 0;
        for (const auto& names : a.names)
            n += std::count(names.begin(), names.end(), "Profile") && std::count(names.begin(), names.end(), "ProfileFactor");
        return n;
    };
    s.service().vehicle_changed(kChangeProfile);
    REQUIRE(s.rig().run_until([&] { return profile_signals() == 1; }));
    s.service().vehicle_changed(kChangeProfile);
    REQUIRE(s.rig().run_until([&] { return profile_signals() == 2; }));
}
