// daemon/commissioning/MotorTest on the daemon's objects over the fakes of the device seam
// (DaemonRig), judged by the fake wire: one thruster at its value and the others at zero; the
// keep-alive stops it without a repeat, and a repeat keeps it; a pilot's command replaces it
// and its keep-alive then leaves the pilot's alone; each refusal named, changing nothing.
#include "daemon/commissioning/motor_test.hpp"

#include "tests/catch.hpp"
#include "tests/unit/fakes/daemon_rig.hpp"

#include <vector>

using namespace caracara;
using namespace caracara::test;

namespace {

// The keep-alive short (its floor), the command timeout far: only the keep-alive stops a test.
const std::string kControl = "loop_rate_hz = 50\ncommand_timeout_ms = 60000\n";
const std::string kSections = "[commissioning]\nmotor_test_keepalive_ms = 50\n";

std::vector<int32_t> one(std::size_t thruster, int32_t value) {
    std::vector<int32_t> v(kMotorCount, 0);
    v[thruster] = value;
    return v;
}

bool each_ordered(DaemonRig& rig, const std::vector<int32_t>& values, long from = 0) {
    const auto ev = rig.wire().events();
    for (std::size_t i = 0; i < values.size(); ++i)
        if (find(ev, [&](const WireEvent& e) { return e.is_order(i, on_wire(values[i])); }, from) < 0)
            return false;
    return true;
}

// An order to `thruster` of anything but `value`.
bool other_order(DaemonRig& rig, std::size_t thruster, int32_t value) {
    return find(rig.wire().events(), [&](const WireEvent& e) {
               return e.kind == WireEvent::Kind::Order && e.thruster == thruster && e.value != on_wire(value);
           }) >= 0;
}

} // namespace

TEST_CASE("MotorTest: one thruster at its value, the others at zero; without a repeat it stops") {
    DaemonRig rig(kControl, kSections);
    rig.run_until_ready();
    MotorTest& t = rig.daemon().motor_test();
    rig.wire().clear();
    REQUIRE(t.run(2, 800, ":1.7").ok());
    CHECK(t.active_thruster() == 2);
    CHECK(t.value() == 800);
    REQUIRE(rig.run_until([&] { return each_ordered(rig, one(2, 800)); }));
    // No repeat: the keep-alive runs out and the thruster is ordered zero.
    REQUIRE(rig.run_until([&] { return t.active_thruster() < 0; }));
    CHECK(rig.vehicle().readings().requested_values() == MotorValues{});
    CHECK(rig.run_until([&] {
        const auto ev = rig.wire().events();
        const long ran = find(ev, [](const WireEvent& e) { return e.is_order(2, on_wire(800)); });
        return find(ev, [](const WireEvent& e) { return e.is_order(2, 0); }, ran) >= 0;
    }));
}

TEST_CASE("MotorTest: repeated within the keep-alive, it goes on") {
    // A keep-alive well above the repeats' spacing: a busy machine's late turn is no lapse.
    DaemonRig rig(kControl, "[commissioning]\nmotor_test_keepalive_ms = 200\n");
    rig.run_until_ready();
    MotorTest& t = rig.daemon().motor_test();
    REQUIRE(t.run(5, -600, ":1.7").ok());
    REQUIRE(rig.run_until([&] { return each_ordered(rig, one(5, -600)); }));
    rig.wire().clear();
    // Repeats, ten per keep-alive, for three keep-alives.
    for (int i = 0; i < 30; ++i) {
        REQUIRE(t.run(5, -600, ":1.7").ok());
        rig.run_for(20);
    }
    CHECK(t.active_thruster() == 5);
    CHECK_FALSE(other_order(rig, 5, -600));
}

TEST_CASE("MotorTest: a pilot's command replaces it, and its keep-alive leaves the pilot's alone") {
    DaemonRig rig(kControl, kSections);
    rig.run_until_ready();
    MotorTest& t = rig.daemon().motor_test();
    REQUIRE(t.run(1, 700, ":1.7").ok());
    const std::vector<int32_t> pilot{100, 200, 300, 400, 500, 600, 700, 800};
    REQUIRE(rig.vehicle().motors().set_thrust(pilot, ":1.9").ok());
    CHECK(t.active_thruster() == -1);
    CHECK(t.value() == 0);
    rig.run_for(200); // past several keep-alives
    CHECK(rig.vehicle().readings().requested_values() == MotorValues{100, 200, 300, 400, 500, 600, 700, 800});
    CHECK(rig.vehicle().readings().controller_client() == ":1.9");
    CHECK(each_ordered(rig, pilot));
}

TEST_CASE("MotorTest: refused for a thruster or value out of range or a killed vehicle, changing nothing") {
    DaemonRig rig(kControl, kSections);
    rig.run_until_ready();
    MotorTest& t = rig.daemon().motor_test();
    const int32_t limit = t.limit();
    CHECK(t.run(-1, 100, ":1.7").status == Status::OutOfRange);
    CHECK(t.run(int32_t(kMotorCount), 100, ":1.7").status == Status::OutOfRange);
    CHECK(t.run(0, limit + 1, ":1.7").status == Status::OutOfRange);
    CHECK(t.run(0, -limit - 1, ":1.7").status == Status::OutOfRange);
    CHECK(t.active_thruster() == -1);
    CHECK(rig.vehicle().readings().controller_client().empty());
    REQUIRE(t.run(0, limit, ":1.7").ok()); // the limit itself is allowed
    REQUIRE(rig.vehicle().kill(KillSource::DBus, "test").ok());
    CHECK(t.active_thruster() == -1); // the kill ended it
    rig.wire().clear();
    CHECK(t.run(3, 100, ":1.7").status == Status::Killed);
    rig.run_for(50);
    CHECK(find(rig.wire().events(), [](const WireEvent& e) { return e.kind == WireEvent::Kind::Order && e.value != 0; }) < 0);
}
