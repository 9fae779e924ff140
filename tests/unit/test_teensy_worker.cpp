// TeensyWorker on an sd-event loop of its own: jobs run in order on its thread, their results
// come back on the loop's, and a job held on the wire (a hung Teensy) does not hold the loop.
#include "daemon/teensy/teensy_worker.hpp"

#include "core/config.hpp"
#include "tests/unit/fakes/fake_device_io.hpp"
#include "tests/unit/fakes/fake_wire.hpp"

#include "tests/catch.hpp"

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

using namespace caracara;
using namespace caracara::test;

namespace {

struct WorkerRig {
    WorkerRig() {
        sd_event_new(&event);
        REQUIRE(worker.start(event, 0).empty());
    }
    ~WorkerRig() {
        worker.stop();
        sd_event_unref(event);
    }
    // Runs the loop until `done()` or the timeout.
    bool run_until(const std::function<bool()>& done, int timeout_ms = 3000) {
        const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
        while (!done() && std::chrono::steady_clock::now() < end)
            sd_event_run(event, 10'000);
        return done();
    }
    FakeWire wire;
    DaemonConfig config;
    FakeDeviceIo io{wire, config};
    SpiDev spi{io, "/dev/spidev0.0"};
    TeensyLink link{spi};
    TeensyWorker worker{link};
    sd_event* event = nullptr;
};

} // namespace

TEST_CASE("jobs run in order on the worker's thread; their results come back on the loop's") {
    WorkerRig rig;
    const auto loop_thread = std::this_thread::get_id();
    std::vector<int> ran, done;
    std::atomic<bool> off_loop{true};
    for (int i = 0; i < 5; ++i)
        rig.worker.submit([&, i] { ran.push_back(i); off_loop = off_loop && std::this_thread::get_id() != loop_thread; },
                          [&, i] { CHECK(std::this_thread::get_id() == loop_thread); done.push_back(i); });
    REQUIRE(rig.run_until([&] { return done.size() == 5; }));
    CHECK(ran == std::vector<int>{0, 1, 2, 3, 4});
    CHECK(done == std::vector<int>{0, 1, 2, 3, 4});
    CHECK(off_loop);
    CHECK(rig.worker.idle());
}

TEST_CASE("a job held on the wire does not hold the loop; a poll's result waits for collect()") {
    WorkerRig rig;
    std::atomic<bool> release{false};
    bool held_done = false, poll_done = false;
    rig.worker.submit([&] { while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(1)); },
                      [&] { held_done = true; });
    // The loop keeps running its timers while the job is held.
    int ticks = 0;
    sd_event_source* t = nullptr;
    uint64_t now = 0;
    sd_event_now(rig.event, CLOCK_MONOTONIC, &now);
    sd_event_add_time(
        rig.event, &t, CLOCK_MONOTONIC, now, 1,
        [](sd_event_source* s, uint64_t usec, void* ud) {
            ++*static_cast<int*>(ud);
            sd_event_source_set_time(s, usec + 5000);
            return 0;
        },
        &ticks);
    sd_event_source_set_enabled(t, SD_EVENT_ON);
    REQUIRE(rig.run_until([&] { return ticks >= 10; }));
    CHECK_FALSE(held_done);
    release = true;
    REQUIRE(rig.run_until([&] { return held_done; }));
    // A job submitted without a wake-up: its done runs at collect(), not on its own.
    std::atomic<bool> worked{false};
    rig.worker.submit([&] { worked = true; }, [&] { poll_done = true; }, false);
    while (!worked)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    sd_event_run(rig.event, 20'000);
    CHECK_FALSE(poll_done);
    rig.worker.collect();
    CHECK(poll_done);
    sd_event_source_unref(t);
}
