// ThrusterBus and its BusWorker on the in-process fake of the device seam (FakeDeviceIo):
// what reaches the wire when a kill's zeros overtake queued orders or queue behind them, a
// queued order replaced by a newer one, when_idle, and the bus's and each thruster's health.
#include "daemon/bus/thruster_bus.hpp"

#include "core/clock.hpp"
#include "core/safety.hpp"
#include "tests/unit/fakes/daemon_rig.hpp"
#include "tests/unit/fakes/fake_device_io.hpp"

#include "tests/catch.hpp"

#include <functional>
#include <optional>
#include <stdexcept>
#include <string>

using namespace caracara;
using namespace caracara::test;
using Kind = WireEvent::Kind;

namespace {

// The failsafes as ThrusterHealth sees them: thruster-unreachable pushed (holds, with its
// reason) and cleared.
class Gate final : public FailsafeGate {
public:
    Result clear_kill_refusal() const override { return {}; }
    void push(FailsafeCondition c, bool holds, std::string_view why) override {
        REQUIRE(c == FailsafeCondition::ThrusterUnreachable);
        (holds ? lost : cleared).emplace_back(why);
    }
    std::vector<std::string> lost;
    std::vector<std::string> cleared;
};

class Lockups final : public BusMonitor::Listener {
public:
    void bus_locked_up(const std::string& reason) override { reasons.push_back(reason); }
    void bus_back() override {}
    std::vector<std::string> reasons;
};

// A ThrusterBus on the fake adapter, with its worker started on an sd-event loop of its own.
struct BusRig {
    FakeWire wire;
    DaemonConfig config = *parse_config_string("", "defaults").config;
    FakeDeviceIo io{wire, config};
    VehicleEvents events;
    ThrusterBus bus{io, config, events};
    sd_event* event = nullptr;
    std::vector<BusJob> done;

    BusRig() {
        if (sd_event_new(&event) < 0 || bus.open() < 0)
            throw std::runtime_error("bus rig");
        if (!bus.start(event, 0, [this](const BusJob& j) { done.push_back(j); }).empty())
            throw std::runtime_error("bus worker");
    }
    ~BusRig() {
        bus.stop();
        sd_event_unref(event);
    }
    bool run_until(const std::function<bool()>& pred, int timeout_ms = 3000) {
        const uint64_t end = monotonic_ns() + ms_to_ns(static_cast<uint64_t>(timeout_ms));
        while (!pred() && monotonic_ns() < end)
            sd_event_run(event, 10'000);
        return pred();
    }
    // The first transfer is on the wire and held there; what follows queues behind it.
    void hang_first(std::size_t i, int32_t value) {
        wire.hold();
        bus.send_order(i, value);
        if (!run_until([&] { return wire.transfer_waiting(); }))
            throw std::runtime_error("no transfer reached the wire");
    }
    void release_and_drain() {
        wire.release();
        if (!run_until([&] { return bus.worker().idle(); }))
            throw std::runtime_error("the worker did not drain");
    }
};

long order_at(const std::vector<WireEvent>& ev, std::size_t i, int32_t v) {
    return find(ev, [&](const WireEvent& e) { return e.is_order(i, on_wire(v)); });
}

} // namespace

TEST_CASE("each order reaches its thruster with its value; ordered_value is what was handed over") {
    BusRig r;
    for (std::size_t i = 0; i < 8; ++i)
        r.bus.send_order(i, 1000 + 100 * static_cast<int32_t>(i));
    REQUIRE(r.run_until([&] { return r.bus.worker().idle(); }));
    const auto ev = r.wire.events();
    for (std::size_t i = 0; i < 8; ++i) {
        CHECK(order_at(ev, i, 1000 + 100 * static_cast<int32_t>(i)) >= 0);
        CHECK(r.bus.ordered_value(i) == 1000 + 100 * static_cast<int32_t>(i));
        CHECK(r.bus.thruster(i).online());
    }
    CHECK(r.done.size() == 8);
    CHECK(r.bus.monitor().telemetry().transactions == 8);
}

TEST_CASE("zeros first: they overtake the queued orders, which are dropped") {
    BusRig r;
    r.hang_first(0, 2000);
    r.bus.send_order(1, 2000);
    r.bus.send_order(2, 2000);
    r.bus.worker().hold_orders(); // a kill: no older non-zero order after its kill output
    r.bus.zero_all(ZeroOrder::First);
    r.release_and_drain();
    const auto ev = r.wire.events();
    CHECK(order_at(ev, 0, 2000) == 0); // the one already on the wire
    CHECK(order_at(ev, 1, 2000) < 0);
    CHECK(order_at(ev, 2, 2000) < 0);
    for (std::size_t i = 0; i < 8; ++i)
        CHECK(order_at(ev, i, 0) > 0);
}

TEST_CASE("zeros behind: what was queued goes out first") {
    BusRig r;
    r.hang_first(0, 2000);
    r.bus.send_order(1, 2000);
    r.bus.send_order(2, 2000);
    r.bus.zero_all(ZeroOrder::Behind);
    r.release_and_drain();
    const auto ev = r.wire.events();
    CHECK(order_at(ev, 1, 2000) >= 0);
    CHECK(order_at(ev, 1, 2000) < order_at(ev, 1, 0));
    CHECK(order_at(ev, 2, 2000) < order_at(ev, 2, 0));
}

TEST_CASE("a newer order takes the place of one still queued for the same thruster") {
    BusRig r;
    r.hang_first(0, 100);
    r.bus.send_order(1, 1000);
    r.bus.send_order(1, 3000);
    r.release_and_drain();
    const auto ev = r.wire.events();
    CHECK(order_at(ev, 1, 1000) < 0);
    CHECK(order_at(ev, 1, 3000) >= 0);
}

TEST_CASE("orders go before the queued status reads") {
    BusRig r;
    r.hang_first(0, 100);
    r.bus.read_status(3);
    r.bus.send_order(4, 1500);
    r.release_and_drain();
    const auto ev = r.wire.events();
    const long read = find(ev, [](const WireEvent& e) { return e.kind == Kind::StatusRead && e.thruster == 3; });
    REQUIRE(read >= 0);
    CHECK(order_at(ev, 4, 1500) < read);
}

TEST_CASE("when_idle runs once the transfers handed over are on the wire, at once when idle") {
    BusRig r;
    bool ran = false;
    r.bus.when_idle([&] { ran = true; });
    CHECK(ran);
    r.hang_first(0, 100);
    r.bus.send_order(1, 100);
    std::optional<std::size_t> seen;
    r.bus.when_idle([&] { seen = r.wire.events().size(); });
    CHECK_FALSE(seen);
    r.release_and_drain();
    REQUIRE(seen);
    CHECK(*seen == 2);
}

TEST_CASE("a thruster failing three transfers in a row is unreachable; the failsafes hear it once; it answers again") {
    BusRig r;
    Gate gate;
    r.bus.health().set_failsafes(&gate);
    r.wire.fail(3, ENXIO);
    for (int n = 0; n < 5; ++n) {
        r.bus.send_order(3, 0);
        r.bus.send_order(0, 0); // the bus itself works
        REQUIRE(r.run_until([&] { return r.bus.worker().idle(); }));
        CHECK(r.bus.health().first_unreachable().has_value() == (n >= 2));
    }
    REQUIRE(gate.lost.size() == 1);
    CHECK(gate.lost[0].find("thruster 3 unreachable") != std::string::npos);
    CHECK(r.bus.monitor().telemetry().state == BusState::Ok);
    r.wire.fail(3, 0);
    r.bus.send_order(3, 0);
    REQUIRE(r.run_until([&] { return r.bus.worker().idle(); }));
    CHECK_FALSE(r.bus.health().first_unreachable());
    CHECK(gate.cleared.size() == 1); // thruster-unreachable ends with the last one answering
    Gate late;
    r.wire.fail(6, ENXIO);
    for (int n = 0; n < 3; ++n) {
        r.bus.send_order(6, 0);
        REQUIRE(r.run_until([&] { return r.bus.worker().idle(); }));
    }
    r.bus.health().set_failsafes(&late); // told at once of the one already unreachable
    CHECK(late.lost.size() == 1);
}

TEST_CASE("a bus on which every transfer times out is locked up: the monitor tells its listener") {
    BusRig r;
    Lockups lockups;
    r.bus.monitor().set_listener(&lockups);
    for (std::size_t i = 0; i < 8; ++i)
        r.wire.fail(i, ETIMEDOUT);
    for (int n = 0; n < 4 && lockups.reasons.empty(); ++n) {
        r.bus.send_order(static_cast<std::size_t>(n), 0);
        REQUIRE(r.run_until([&] { return r.bus.worker().idle(); }));
    }
    REQUIRE(lockups.reasons.size() == 1);
    CHECK(r.bus.monitor().telemetry().errors >= LockupDetector::kBusErrors);
    // While recovering, the failures say nothing new and no transfer is handed over.
    r.bus.set_recovering(true);
    r.bus.zero_all();
    CHECK(r.bus.worker().idle());
    r.bus.set_recovering(false);
}
