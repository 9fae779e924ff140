// The control loop's policies, without sd-event: what goes on the wire next, when a run of
// transfer errors is a locked bus, and how recovery attempts are spaced and given up.
#include "core/lockup_detector.hpp"
#include "core/order_schedule.hpp"
#include "core/recovery_policy.hpp"

#include "tests/catch.hpp"

#include <vector>

using namespace caracara;
using Kind = OrderSchedule::Kind;

namespace {
std::vector<OrderSchedule::Item> drain(OrderSchedule& s, bool bus_usable = true) {
    std::vector<OrderSchedule::Item> out;
    for (auto it = s.next(bus_usable); it.kind != Kind::None; it = s.next(bus_usable))
        out.push_back(it);
    return out;
}
} // namespace

TEST_CASE("a cycle sends every order, then the status reads round robin, then the Teensy slot") {
    OrderSchedule s(8);
    s.start_cycle(2, true);
    auto items = drain(s);
    REQUIRE(items.size() == 8 + 2 + 1);
    for (size_t i = 0; i < 8; ++i)
        CHECK((items[i].kind == Kind::Order && items[i].index == i));
    CHECK((items[8].kind == Kind::Status && items[8].index == 0));
    CHECK((items[9].kind == Kind::Status && items[9].index == 1));
    CHECK(items[10].kind == Kind::Teensy);
    // The next cycle's reads continue where this one stopped.
    s.start_cycle(3, false);
    items = drain(s);
    REQUIRE(items.size() == 8 + 3);
    CHECK(items[8].index == 2);
    CHECK(items[9].index == 3);
    CHECK(items[10].index == 4);
}

TEST_CASE("the status round robin wraps around the thrusters") {
    OrderSchedule s(3);
    std::vector<size_t> read;
    for (int c = 0; c < 4; ++c) {
        s.start_cycle(1, false);
        for (auto& it : drain(s))
            if (it.kind == Kind::Status)
                read.push_back(it.index);
    }
    CHECK(read == std::vector<size_t>{0, 1, 2, 0});
}

TEST_CASE("a changed order jumps ahead of the status reads") {
    OrderSchedule s(8);
    s.start_cycle(1, true);
    for (int i = 0; i < 8; ++i)
        REQUIRE(s.next(true).kind == Kind::Order);
    s.mark_order(5);
    auto it = s.next(true);
    CHECK((it.kind == Kind::Order && it.index == 5));
    CHECK(s.next(true).kind == Kind::Status);
}

TEST_CASE("a tick during a burst does not restart it") {
    OrderSchedule s(8);
    s.start_cycle(0, false);
    for (int i = 0; i < 3; ++i)
        REQUIRE(s.next(true).kind == Kind::Order); // 0, 1, 2 sent
    s.start_cycle(0, false);                       // the next tick, burst still going
    auto items = drain(s);
    REQUIRE(items.size() == 5);
    CHECK(items.front().index == 3);
    CHECK(items.back().index == 7);
}

TEST_CASE("while the bus is unusable only the Teensy slot is handed out, and the orders wait") {
    OrderSchedule s(8);
    s.start_cycle(1, true);
    auto items = drain(s, false);
    REQUIRE(items.size() == 1);
    CHECK(items[0].kind == Kind::Teensy);
    CHECK(s.any_order_due());
    s.drop_bus_work();
    CHECK_FALSE(s.any_order_due());
    CHECK(drain(s).empty());
}

TEST_CASE("pop_order hands out only orders") {
    OrderSchedule s(4);
    s.start_cycle(2, true);
    size_t i = 99;
    std::vector<size_t> got;
    while (s.pop_order(i))
        got.push_back(i);
    CHECK(got == std::vector<size_t>{0, 1, 2, 3});
    CHECK(s.next(true).kind == Kind::Status);
}

TEST_CASE("three bus-level errors in a row are a lockup; a NACK between them is not") {
    LockupDetector d(8);
    using T = LockupDetector::Transfer;
    CHECK_FALSE(d.note(T::BusError));
    CHECK_FALSE(d.note(T::BusError));
    CHECK(d.note(T::BusError));
    CHECK(d.reason("ETIMEDOUT") == "3 bus errors in a row, last ETIMEDOUT");
    d.reset();
    CHECK_FALSE(d.note(T::BusError));
    CHECK_FALSE(d.note(T::BusError));
    CHECK_FALSE(d.note(T::DeviceError)); // one absent thruster breaks the run
    CHECK_FALSE(d.note(T::BusError));
}

TEST_CASE("every thruster failing twice in a row is a lockup; one answering resets it") {
    LockupDetector d(8);
    using T = LockupDetector::Transfer;
    for (int i = 0; i < 15; ++i)
        CHECK_FALSE(d.note(T::DeviceError));
    CHECK(d.note(T::DeviceError));
    CHECK(d.reason("Nack") == "every thruster failing, last Nack");
    d.reset();
    for (int i = 0; i < 15; ++i)
        CHECK_FALSE(d.note(T::DeviceError));
    CHECK_FALSE(d.note(T::Ok));
    CHECK_FALSE(d.note(T::DeviceError));
}

TEST_CASE("a bad reply crossed the wire: it clears the count") {
    LockupDetector d(8);
    using T = LockupDetector::Transfer;
    CHECK_FALSE(d.note(T::BusError));
    CHECK_FALSE(d.note(T::BusError));
    CHECK_FALSE(d.note(T::BadReply));
    CHECK_FALSE(d.note(T::BusError));
    CHECK_FALSE(d.note(T::BusError));
    CHECK(d.note(T::BusError));
}

TEST_CASE("recovery backs off exponentially, gives up once, then retries in the background") {
    RecoveryPolicy p(3, 100);
    p.begin(1'000'000'000);
    CHECK(p.next_attempt() == 1);
    auto f = p.failed();
    CHECK_FALSE(f.lost);
    CHECK(f.retry_in_ns == 100'000'000);
    p.next_attempt();
    f = p.failed();
    CHECK_FALSE(f.lost);
    CHECK(f.retry_in_ns == 200'000'000);
    p.next_attempt();
    f = p.failed();
    CHECK(f.lost); // the third failure uses the attempts up: the bus is lost
    CHECK(f.retry_in_ns == RecoveryPolicy::kBackgroundRetryNs);
    p.next_attempt();
    f = p.failed();
    CHECK_FALSE(f.lost); // reported lost once, not at every background retry
    CHECK(f.retry_in_ns == RecoveryPolicy::kBackgroundRetryNs);
    CHECK(p.elapsed_ms(1'250'000'000) == Approx(250.0));
}

TEST_CASE("the backoff never exceeds the background retry period") {
    RecoveryPolicy p(40, 1000);
    p.begin(0);
    for (int i = 0; i < 39; ++i) {
        p.next_attempt();
        CHECK(p.failed().retry_in_ns <= RecoveryPolicy::kBackgroundRetryNs);
    }
}

TEST_CASE("a new recovery starts counting attempts again") {
    RecoveryPolicy p(2, 50);
    p.begin(0);
    p.next_attempt();
    p.next_attempt();
    CHECK(p.failed().lost);
    p.begin(10);
    CHECK(p.next_attempt() == 1);
    CHECK_FALSE(p.failed().lost);
}
