// daemon/loop/LoopWaker on an sd-event loop of its own: a worker thread's wake() runs the
// handler on the loop's thread; wake-ups before the loop gets to them merge into one call; the
// handler runs at its priority, before the loop's less urgent work; closed, it wakes nothing.
#include "daemon/loop/loop_waker.hpp"

#include "core/clock.hpp"
#include "core/safety_config.hpp"
#include "tests/catch.hpp"

#include <functional>
#include <stdexcept>
#include <thread>
#include <vector>

using namespace caracara;

namespace {

EventPtr new_loop() {
    sd_event* e = nullptr;
    if (sd_event_new(&e) < 0)
        throw std::runtime_error("sd_event_new");
    return EventPtr(e);
}

// Runs `event` until `done()` or `give_up_ms` passed (a give-up time, not a bound).
bool run_until(sd_event* event, const std::function<bool()>& done, int give_up_ms) {
    const uint64_t end = monotonic_ns() + ms_to_ns(static_cast<uint64_t>(give_up_ms));
    while (!done() && monotonic_ns() < end)
        sd_event_run(event, 5'000);
    return done();
}

} // namespace

TEST_CASE("LoopWaker: a wake from another thread runs the handler on the loop's thread") {
    EventPtr loop = new_loop();
    LoopWaker w;
    std::vector<std::thread::id> ran_on;
    REQUIRE(w.open(loop.get(), 0, [&] { ran_on.push_back(std::this_thread::get_id()); }).empty());
    std::thread worker([&] { w.wake(); });
    worker.join();
    REQUIRE(run_until(loop.get(), [&] { return !ran_on.empty(); }, 2000));
    CHECK(ran_on[0] == std::this_thread::get_id());
}

TEST_CASE("LoopWaker: wake-ups before the loop gets to them are one call") {
    EventPtr loop = new_loop();
    LoopWaker w;
    int calls = 0;
    REQUIRE(w.open(loop.get(), 0, [&] { ++calls; }).empty());
    std::thread worker([&] {
        for (int i = 0; i < 100; ++i)
            w.wake();
    });
    worker.join();
    REQUIRE(run_until(loop.get(), [&] { return calls > 0; }, 2000));
    run_until(loop.get(), [] { return false; }, 30);
    CHECK(calls == 1);
    w.wake(); // and a later one is a call again
    REQUIRE(run_until(loop.get(), [&] { return calls == 2; }, 2000));
}

TEST_CASE("LoopWaker: the handler runs at its priority, ahead of less urgent work") {
    EventPtr loop = new_loop();
    LoopWaker w;
    std::vector<int> order;
    REQUIRE(w.open(loop.get(), -10, [&] { order.push_back(1); }).empty());
    sd_event_source* s = nullptr;
    REQUIRE(sd_event_add_defer(loop.get(), &s, [](sd_event_source*, void* u) {
        static_cast<std::vector<int>*>(u)->push_back(2);
        return 0;
    }, &order) >= 0);
    SourcePtr later(s);
    sd_event_source_set_priority(s, 10);
    sd_event_source_set_enabled(s, SD_EVENT_ONESHOT);
    w.wake();
    REQUIRE(run_until(loop.get(), [&] { return order.size() == 2; }, 2000));
    CHECK(order == std::vector<int>{1, 2});
}

TEST_CASE("LoopWaker: closed, a wake runs nothing") {
    EventPtr loop = new_loop();
    LoopWaker w;
    int calls = 0;
    REQUIRE(w.open(loop.get(), 0, [&] { ++calls; }).empty());
    w.close();
    w.wake();
    run_until(loop.get(), [] { return false; }, 30);
    CHECK(calls == 0);
}
