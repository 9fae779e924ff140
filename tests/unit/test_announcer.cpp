// dbus/Announcer on an sd-event loop of its own (a bus attached to it, never connected: the
// announcer only defers to the bus's loop): what one flush carries, what waits while orders are
// in flight and what does not, and the counters' tick at every fifth telemetry tick.
#include "dbus/announcer.hpp"
#include "tests/catch.hpp"

#include <stdexcept>
#include <vector>

using namespace caracara;
using namespace caracara::dbus;

namespace {

struct Loop {
    Loop() {
        sd_event* e = nullptr;
        sd_bus* b = nullptr;
        if (sd_event_new(&e) < 0 || sd_bus_new(&b) < 0)
            throw std::runtime_error("sd_event_new / sd_bus_new");
        event.reset(e);
        bus.reset(b);
        if (sd_bus_attach_event(b, e, SD_EVENT_PRIORITY_NORMAL) < 0)
            throw std::runtime_error("sd_bus_attach_event");
    }
    ~Loop() { sd_bus_detach_event(bus.get()); }
    // Runs every pending event (a few turns; nothing here waits on time).
    void run() {
        for (int i = 0; i < 5; ++i)
            sd_event_run(event.get(), 0);
    }
    EventPtr event;
    BusPtr bus;
};

} // namespace

TEST_CASE("Announcer: the changes requested before the loop gets to it go out in one flush") {
    Loop loop;
    std::vector<uint32_t> flushed;
    Announcer a(loop.bus.get(), [&](uint32_t c) { flushed.push_back(c); });
    a.request(kChangeState);
    a.request(kChangeMotors);
    CHECK(flushed.empty()); // deferred to the loop
    loop.run();
    REQUIRE(flushed.size() == 1);
    CHECK(flushed[0] == (kChangeState | kChangeMotors));
    loop.run();
    CHECK(flushed.size() == 1); // once
}

TEST_CASE("Announcer: after the loop's other work of the same turn (kAnnouncePriority)") {
    Loop loop;
    std::vector<int> order;
    Announcer a(loop.bus.get(), [&](uint32_t) { order.push_back(2); });
    a.request(kChangeMotors);
    sd_event_source* s = nullptr;
    REQUIRE(sd_event_add_defer(loop.event.get(), &s, [](sd_event_source*, void* u) {
        static_cast<std::vector<int>*>(u)->push_back(1);
        return 0;
    }, &order) >= 0);
    SourcePtr work(s);
    sd_event_source_set_enabled(s, SD_EVENT_ONESHOT);
    loop.run();
    CHECK(order == std::vector<int>{1, 2});
}

TEST_CASE("Announcer: while orders are in flight, motors, controller and telemetry wait; a state change goes and takes them") {
    Loop loop;
    std::vector<uint32_t> flushed;
    Announcer a(loop.bus.get(), [&](uint32_t c) { flushed.push_back(c); });
    a.hold(true);
    a.request(kChangeMotors);
    a.request(kChangeController);
    a.request(kTelemetryTick);
    loop.run();
    CHECK(flushed.empty());
    a.hold(false);
    loop.run();
    REQUIRE(flushed.size() == 1);
    CHECK(flushed[0] == (kChangeMotors | kChangeController | kTelemetryTick));

    flushed.clear();
    a.hold(true);
    a.request(kChangeMotors);
    loop.run();
    CHECK(flushed.empty());
    a.request(kChangeState); // a kill's state does not wait
    loop.run();
    REQUIRE(flushed.size() == 1);
    CHECK(flushed[0] == (kChangeMotors | kChangeState));
    a.hold(false); // nothing left
    loop.run();
    CHECK(flushed.size() == 1);
}

TEST_CASE("Announcer: the counters go out at every fifth telemetry tick") {
    Loop loop;
    std::vector<uint32_t> flushed;
    Announcer a(loop.bus.get(), [&](uint32_t c) { flushed.push_back(c); });
    for (int i = 0; i < 10; ++i) {
        a.request(kTelemetryTick);
        loop.run();
    }
    REQUIRE(flushed.size() == 10);
    for (std::size_t i = 0; i < flushed.size(); ++i) {
        INFO("tick " << i + 1);
        CHECK(bool(flushed[i] & kCounterTick) == ((i + 1) % 5 == 0));
    }
    // A change that is no tick does not count.
    a.request(kChangeState);
    loop.run();
    CHECK_FALSE(flushed.back() & kCounterTick);
}

TEST_CASE("Announcer: without an event loop, a request is flushed at once") {
    sd_bus* b = nullptr;
    REQUIRE(sd_bus_new(&b) >= 0);
    BusPtr bus(b);
    std::vector<uint32_t> flushed;
    Announcer a(bus.get(), [&](uint32_t c) { flushed.push_back(c); });
    a.request(kChangeLeds);
    REQUIRE(flushed.size() == 1);
    CHECK(flushed[0] == kChangeLeds);
}
