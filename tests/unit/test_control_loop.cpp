// The control loop on the in-process fakes of the device seam: the orders it is handed go out
// with their values (changed ones at once, the rest refreshed by the tick), the status reads
// go round, and the zeros go first or behind as asked.
#include "tests/unit/fakes/daemon_rig.hpp"

#include "core/clock.hpp"

#include "tests/catch.hpp"

#include <algorithm>
#include <array>
#include <set>

using namespace caracara;
using namespace caracara::test;
using Kind = WireEvent::Kind;

namespace {
MotorValues values(int32_t base) {
    MotorValues m{};
    for (std::size_t i = 0; i < m.size(); ++i)
        m[i] = base * static_cast<int32_t>(i + 1);
    return m;
}

// Every thruster's order with its value of `m` (as the wire carries it) is in `events`.
bool all_ordered(const std::vector<WireEvent>& events, const MotorValues& m) {
    for (std::size_t i = 0; i < m.size(); ++i)
        if (find(events, [&](const WireEvent& e) { return e.is_order(i, on_wire(m[i])); }) < 0)
            return false;
    return true;
}
} // namespace

TEST_CASE("a changed order goes out at once, not at the next tick") {
    DaemonRig rig("loop_rate_hz = 2\n"); // a tick every 500 ms refreshes all eight, thruster 0 first
    rig.run_until_ready();
    MotorValues m{};
    rig.loop().demand_changed(m); // what stands now: nothing changed, nothing due
    // Right after a cycle's work (its orders, then its status read): the next tick is far.
    const uint64_t cycles = rig.loop().cycles();
    REQUIRE(rig.run_until([&] { return rig.loop().cycles() > cycles; }));
    rig.wire().clear();
    const auto is_read = [](const WireEvent& e) { return e.kind == Kind::StatusRead; };
    // The status read is the cycle's last transfer (its results are taken at the next tick).
    REQUIRE(rig.run_until([&] { return find(rig.wire().events(), is_read) >= 0; }));
    rig.wire().clear();
    m[2] = 3000;
    rig.loop().demand_changed(m);
    const auto is_order = [](const WireEvent& e) { return e.kind == Kind::Order; };
    REQUIRE(rig.run_until([&] { return find(rig.wire().events(), is_order) >= 0; }, 1000));
    const auto ev = rig.wire().events();
    CHECK(ev[static_cast<std::size_t>(find(ev, is_order))].is_order(2, on_wire(3000)));
}

TEST_CASE("the tick refreshes every order with the value it was handed, and reads each thruster's status in turn") {
    DaemonRig rig("loop_rate_hz = 100\n");
    rig.run_until_ready();
    const MotorValues m = values(500);
    rig.loop().demand_changed(m);
    REQUIRE(rig.run_until([&] { return all_ordered(rig.wire().events(), m); }));
    rig.wire().clear();
    // About twenty ticks: each thruster refreshed at least five times, each one's status read.
    std::array<int, 8> orders{};
    std::set<std::size_t> read;
    const auto count = [&] {
        orders = {};
        read.clear();
        for (const WireEvent& e : rig.wire().events()) {
            if (e.kind == Kind::Order)
                ++orders[e.thruster];
            else if (e.kind == Kind::StatusRead)
                read.insert(e.thruster);
        }
        return read.size() == 8 && *std::min_element(orders.begin(), orders.end()) >= 5;
    };
    CHECK(rig.run_until(count));
    for (const WireEvent& e : rig.wire().events())
        if (e.kind == Kind::Order)
            CHECK(e.value == on_wire(m[e.thruster])); // nothing but the value handed down
}

TEST_CASE("zeros behind: the orders already due reach the wire first") {
    DaemonRig rig("loop_rate_hz = 2\n");
    rig.run_until_ready();
    rig.wire().clear();
    const MotorValues m = values(700);
    rig.loop().demand_changed(m);
    rig.loop().zero_all(ZeroOrder::Behind); // before the loop ran: all eight still due
    // Waited for on the wire: the bus is idle only between a cycle's results and the next tick.
    REQUIRE(rig.run_until([&] { return all_ordered(rig.wire().events(), MotorValues{}); }));
    const auto ev = rig.wire().events();
    for (std::size_t i = 0; i < 8; ++i) {
        const long sent = find(ev, [&](const WireEvent& e) { return e.is_order(i, on_wire(m[i])); });
        const long zero = find(ev, [&](const WireEvent& e) { return e.is_order(i, 0); }, sent); // its zero, after it
        REQUIRE(sent >= 0);
        CHECK(zero > sent);
    }
}

TEST_CASE("zeros first: the orders still due never reach the wire") {
    DaemonRig rig("loop_rate_hz = 2\n");
    rig.run_until_ready();
    rig.wire().clear();
    rig.loop().demand_changed(values(700));
    rig.loop().zero_all(ZeroOrder::First);
    rig.run_for(100);
    const auto ev = rig.wire().events();
    for (std::size_t i = 0; i < 8; ++i)
        CHECK(find(ev, [&](const WireEvent& e) { return e.is_order(i, 0); }) >= 0);
    CHECK(find(ev, [](const WireEvent& e) { return e.kind == Kind::Order && e.value != 0; }) < 0);
}

TEST_CASE("a recovered bus gets every standing order again") {
    DaemonRig rig("loop_rate_hz = 2\n");
    rig.run_until_ready();
    const MotorValues m = values(300);
    const auto all_on_wire = [&] { return all_ordered(rig.wire().events(), m); };
    rig.loop().demand_changed(m);
    REQUIRE(rig.run_until(all_on_wire));
    rig.wire().clear();
    rig.loop().resend_orders();
    // At once (the fake seam answers in microseconds), not with the next tick's refresh up to
    // 500 ms later.
    CHECK(rig.run_until(all_on_wire, 100));
}

TEST_CASE("the loop counts its cycles and is healthy while they complete") {
    DaemonRig rig("loop_rate_hz = 100\n");
    rig.run_until_ready();
    const uint64_t before = rig.loop().cycles();
    rig.run_for(100);
    CHECK(rig.loop().cycles() >= before + 5);
    CHECK(rig.loop().healthy(monotonic_ns()));
}

TEST_CASE("a time taken before the last cycle ended is a healthy loop, not a stale one") {
    // The watchdog's look, late in a loaded event loop, once judged with the time its timer was
    // due: a cycle that ended since then wrapped the age round (unsigned) and systemd was not fed.
    DaemonRig rig("loop_rate_hz = 100\n");
    const uint64_t before = monotonic_ns();
    rig.run_until_ready();
    const uint64_t cycles = rig.loop().cycles();
    REQUIRE(rig.run_until([&] { return rig.loop().cycles() > cycles + 2; }));
    CHECK(rig.loop().healthy(before));
    CHECK(rig.loop().healthy(monotonic_ns()));
    CHECK_FALSE(rig.loop().healthy(monotonic_ns() + 2'000'000'000ull)); // a loop 2 s without a cycle
}
