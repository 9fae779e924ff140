// daemon/loop/DeadlineTimer on an sd-event loop of its own: it fires once, never before the time
// it was armed for; moving the time moves the firing; kNever disarms; once fired it can be armed
// again for the same time (the end of arming and the command timeout land on it).
#include "daemon/loop/deadline_timer.hpp"

#include "core/clock.hpp"
#include "core/safety_config.hpp"
#include "tests/catch.hpp"

#include <functional>
#include <stdexcept>
#include <vector>

using namespace caracara;

namespace {

struct Loop {
    Loop() {
        sd_event* e = nullptr;
        if (sd_event_new(&e) < 0)
            throw std::runtime_error("sd_event_new");
        event.reset(e);
    }
    // Runs the loop until `done()` or `give_up_ms` passed (a give-up time, not a bound).
    bool run_until(const std::function<bool()>& done, int give_up_ms) {
        const uint64_t end = monotonic_ns() + ms_to_ns(static_cast<uint64_t>(give_up_ms));
        while (!done() && monotonic_ns() < end)
            sd_event_run(event.get(), 5'000);
        return done();
    }
    void run_for(int ms) { run_until([] { return false; }, ms); }
    EventPtr event;
};

} // namespace

TEST_CASE("DeadlineTimer: fires once, not before its time") {
    Loop loop;
    std::vector<uint64_t> fired;
    DeadlineTimer t([&] { fired.push_back(monotonic_ns()); });
    REQUIRE(t.start(loop.event.get()).empty());
    loop.run_for(30);
    CHECK(fired.empty()); // off until armed
    const uint64_t at = monotonic_ns() + ms_to_ns(30);
    t.arm(at);
    REQUIRE(loop.run_until([&] { return !fired.empty(); }, 2000));
    CHECK(fired[0] >= at);
    t.arm(at); // the same time again, after it fired: once more
    REQUIRE(loop.run_until([&] { return fired.size() == 2; }, 2000));
    loop.run_for(60);
    CHECK(fired.size() == 2);
}

TEST_CASE("DeadlineTimer: armed again for a later time, it fires at the later one only") {
    Loop loop;
    std::vector<uint64_t> fired;
    DeadlineTimer t([&] { fired.push_back(monotonic_ns()); });
    REQUIRE(t.start(loop.event.get()).empty());
    const uint64_t first = monotonic_ns() + ms_to_ns(20);
    const uint64_t later = first + ms_to_ns(60);
    t.arm(first);
    t.arm(later);
    REQUIRE(loop.run_until([&] { return !fired.empty(); }, 2000));
    CHECK(fired[0] >= later);
    loop.run_for(60);
    CHECK(fired.size() == 1);
}

TEST_CASE("DeadlineTimer: kNever disarms; before start() arming does nothing") {
    Loop loop;
    int fired = 0;
    DeadlineTimer t([&] { ++fired; });
    t.arm(monotonic_ns()); // not started: no source to arm
    REQUIRE(t.start(loop.event.get()).empty());
    loop.run_for(30);
    CHECK(fired == 0);
    t.arm(monotonic_ns() + ms_to_ns(20));
    t.arm(DeadlineTimer::kNever);
    loop.run_for(80);
    CHECK(fired == 0);
    t.arm(monotonic_ns()); // armed again after kNever: fires
    REQUIRE(loop.run_until([&] { return fired == 1; }, 2000));
    t.stop();
    t.arm(monotonic_ns());
    loop.run_for(30);
    CHECK(fired == 1);
}
