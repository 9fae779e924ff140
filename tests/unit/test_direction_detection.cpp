// daemon/commissioning/DirectionDetection (with its AttitudeSamples and DirectionFindings) on the
// daemon's objects over the fakes of the device seam (DaemonRig), the Teensy the simulator's own
// model (FakeTeensyIo) reporting the attitude of a vehicle in the pool (PoolVehicle) that turns,
// along what the mixing says, while a thruster's last order on the fake wire is not zero: each
// thruster pulsed alone, in turn, at detect_pulse_value and ordered zero after; the mounting it
// found; refused by name while one runs, killed or without a Teensy; ended by a kill (the pulse
// zeroed at once), by another client's command, by a vehicle that will not hold still, by the
// Teensy falling silent; a stalled poll (the Teensy's frame held on the wire) is no reading: not
// taken for a vehicle holding still, nor measured as a pulse's end.
#include "daemon/commissioning/direction_detection.hpp"

#include "tests/catch.hpp"
#include "tests/unit/fakes/daemon_rig.hpp"
#include "tests/unit/fakes/fake_teensy_io.hpp"
#include "tests/unit/fakes/pool_vehicle.hpp"

#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

using namespace caracara;
using namespace caracara::test;

namespace {

// The shortest pulse [commissioning] allows, and with DetectionRig's default the shortest settle
// window, so that eight thrusters take seconds (the settle's timeout left at its default: a late
// loop, under an emulator, still settles).
const std::string kSections = "[commissioning]\ndetect_pulse_ms = 300\n";
// At 100 Hz each orientation axis is read every 40 ms (one frame a cycle, four slots). The
// command timeout far: the zeros on the wire are the detection's own, not the timeout's.
const std::string kControl = "loop_rate_hz = 100\ncommand_timeout_ms = 60000\n";
constexpr int32_t kPulse = 3000; // detect_pulse_value's default
// Eight thrusters, each a settle of three windows and a pulse: a few seconds; the give-up far.
constexpr int kRunGiveUpMs = 30000;
constexpr double kTurnRad = PoolVehicle::kTurnRad;

// A DaemonRig whose Teensy reports the pool's vehicle; armed, the Teensy answering.
struct DetectionRig {
    // `commissioning`, `spi`: those tables' further keys; the still window, short for speed.
    explicit DetectionRig(const std::string& commissioning = "", const std::string& spi = "", int settle_ms = 100)
        : rig(kControl,
              kSections + "detect_settle_ms = " + std::to_string(settle_ms) + "\n" + commissioning + "[spi]\nfitted = true\n" + spi,
              false, &teensy),
          pool(rig, teensy) {
        rig.run_until_ready();
        REQUIRE(rig.run_until([&] { return rig.daemon().teensy().telemetry().online; }));
    }
    DirectionDetection& detection() { return rig.daemon().directions(); }
    // Runs the detection for `client` to its end.
    Result run(const std::string& client = ":1.7") {
        std::optional<Result> end;
        detection().run(client, [&](const Result& r) { end = r; });
        REQUIRE(rig.run_until([&] { return end.has_value(); }, kRunGiveUpMs));
        return *end;
    }

    FakeTeensyIo teensy{SpiSettings{}.device};
    DaemonRig rig;
    PoolVehicle pool;
};

// The Teensy's frames held on the wire for the scope (a stalled poll), released however the
// test leaves it: a frame still held would keep the rig's Teensy worker from stopping.
struct StalledPoll {
    explicit StalledPoll(FakeTeensyIo& t) : teensy(t) { teensy.hold(true); }
    ~StalledPoll() { teensy.hold(false); }
    StalledPoll(const StalledPoll&) = delete;
    StalledPoll& operator=(const StalledPoll&) = delete;
    FakeTeensyIo& teensy;
};

std::vector<DirectionVerdict> verdicts(const DirectionDetection& d) {
    std::vector<DirectionVerdict> out;
    for (std::size_t i = 0; i < d.judged(); ++i)
        out.push_back(d.findings()[i].judgement.verdict);
    return out;
}

bool nonzero_order(const WireEvent& e) { return e.kind == WireEvent::Kind::Order && e.value != 0; }

// Every thruster's last order on the wire is zero.
bool all_zero(const std::vector<WireEvent>& ev) {
    std::array<int32_t, kMotorCount> last{};
    for (const WireEvent& e : ev)
        if (e.kind == WireEvent::Kind::Order)
            last[e.thruster] = e.value;
    return last == std::array<int32_t, kMotorCount>{};
}

} // namespace

TEST_CASE("DirectionDetection: each thruster pulsed alone, in turn, then zero; the reversed ones found") {
    DetectionRig d;
    d.pool.mounting[2] = -1; // a horizontal one
    d.pool.mounting[5] = -1; // a vertical one
    d.rig.wire().clear();
    REQUIRE(d.run().ok());
    // Its last zeros reach the wire at the next cycle.
    REQUIRE(d.rig.run_until([&] { return all_zero(d.rig.wire().events()); }));
    const DirectionDetection& det = d.detection();
    CHECK_FALSE(det.running());
    CHECK(det.pulsing() == -1);
    using V = DirectionVerdict;
    CHECK(verdicts(det) == std::vector<V>{V::Ok, V::Ok, V::Reversed, V::Ok, V::Ok, V::Reversed, V::Ok, V::Ok});
    // What it measured: the turn the pulse made, along the mixing's rotation (the Teensy reads
    // one axis a cycle: a sample or two of the window may predate the turn), at most the turn.
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        CHECK(std::abs(det.findings()[i].judgement.along) > kTurnRad / 2);
        CHECK(std::abs(det.findings()[i].judgement.along) <= kTurnRad + 1e-6);
    }
    // The fragment flips the two found reversed, and only them.
    const std::string f = det.fragment();
    std::size_t flipped = 0;
    for (std::size_t at = f.find("reversed = true"); at != std::string::npos; at = f.find("reversed = true", at + 1))
        ++flipped;
    CHECK(flipped == 2);
    CHECK(f.find("[[thruster]] # motor 2: reversed") != std::string::npos);
    CHECK(f.find("[[thruster]] # motor 5: reversed") != std::string::npos);
    CHECK_FALSE(d.rig.config().thrusters[2].reversed); // the configuration itself never changes

    // The wire: thruster i's pulse, at the pulse value, alone, after i-1's was ordered zero.
    const auto ev = d.rig.wire().events();
    long after = 0;
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        INFO("thruster " << i);
        const long first = find(ev, [i](const WireEvent& e) { return e.thruster == i && nonzero_order(e); }, after);
        REQUIRE(first >= 0);
        const long stop = find(ev, [i](const WireEvent& e) { return e.is_order(i, 0); }, first);
        REQUIRE(stop > first);
        for (long k = first; k < stop; ++k) {
            const WireEvent& e = ev[std::size_t(k)];
            if (e.kind != WireEvent::Kind::Order)
                continue;
            CHECK(e.value == (e.thruster == i ? on_wire(kPulse) : 0));
        }
        // No pulse of it before, none after its zero.
        CHECK(find(ev, [i](const WireEvent& e) { return e.thruster == i && nonzero_order(e); }, 0) == first);
        CHECK(find(ev, [i](const WireEvent& e) { return e.thruster == i && nonzero_order(e); }, stop) < 0);
        after = stop;
    }
}

TEST_CASE("DirectionDetection: a thruster that turns nothing (its lead off) is inconclusive, kept as configured") {
    DetectionRig d;
    d.pool.mounting[3] = 0;
    REQUIRE(d.run().ok());
    const DirectionDetection& det = d.detection();
    using V = DirectionVerdict;
    CHECK(verdicts(det) == std::vector<V>{V::Ok, V::Ok, V::Ok, V::Inconclusive, V::Ok, V::Ok, V::Ok, V::Ok});
    CHECK(det.findings()[3].judgement.margin < 1.0);
    CHECK(det.fragment().find("motor 3: inconclusive, kept as configured") != std::string::npos);
}

TEST_CASE("DirectionDetection: refused while one runs, the running one going on") {
    DetectionRig d;
    DirectionDetection& det = d.detection();
    std::optional<Result> first, second;
    det.run(":1.7", [&](const Result& r) { first = r; });
    REQUIRE(det.running());
    det.run(":1.9", [&](const Result& r) { second = r; });
    REQUIRE(second.has_value());
    CHECK(second->status == Status::Busy);
    CHECK(second->message == "a direction detection is running");
    CHECK(d.rig.vehicle().readings().controller_client() == ":1.7");
    REQUIRE(d.rig.run_until([&] { return det.pulsing() == 0; }, kRunGiveUpMs));
    CHECK_FALSE(first.has_value());
    // Ended here, its result into `first` while it lives (the rig's stop would complete it later).
    REQUIRE(d.rig.vehicle().kill(KillSource::DBus, "test").ok());
    REQUIRE(d.rig.run_until([&] { return first.has_value(); }));
    CHECK(first->status == Status::Killed);
}

TEST_CASE("DirectionDetection: refused while killed, and without a Teensy; nothing ordered") {
    SECTION("killed") {
        DetectionRig d;
        REQUIRE(d.rig.vehicle().kill(KillSource::DBus, "test").ok());
        d.rig.wire().clear();
        CHECK(d.run().status == Status::Killed);
        d.rig.run_for(100);
        CHECK(find(d.rig.wire().events(), nonzero_order) < 0);
        CHECK(d.detection().judged() == 0);
    }
    SECTION("no Teensy") {
        DaemonRig rig(kControl, kSections); // [spi] not fitted, no node
        rig.run_until_ready();
        std::optional<Result> end;
        rig.daemon().directions().run(":1.7", [&](const Result& r) { end = r; });
        REQUIRE(end.has_value());
        CHECK(end->status == Status::LinkError);
        CHECK(end->message.find("Teensy is offline") != std::string::npos);
        CHECK(rig.vehicle().readings().controller_client().empty());
        CHECK_FALSE(rig.daemon().directions().running());
    }
}

TEST_CASE("DirectionDetection: a kill during a pulse ends it Killed; the pulse is zeroed and not resumed") {
    DetectionRig d;
    DirectionDetection& det = d.detection();
    std::optional<Result> end;
    det.run(":1.7", [&](const Result& r) { end = r; });
    REQUIRE(d.rig.run_until([&] {
        return det.pulsing() == 0 && find(d.rig.wire().events(), [](const WireEvent& e) { return e.is_order(0, on_wire(kPulse)); }) >= 0;
    }, kRunGiveUpMs));
    const long killed_at = long(d.rig.wire().events().size());
    REQUIRE(d.rig.vehicle().kill(KillSource::DBus, "test").ok());
    REQUIRE(d.rig.run_until([&] { return end.has_value(); }));
    CHECK(end->status == Status::Killed);
    CHECK_FALSE(det.running());
    d.rig.run_for(200); // past steps it would have taken
    const auto ev = d.rig.wire().events();
    CHECK(find(ev, [](const WireEvent& e) { return e.is_order(0, 0); }, killed_at) >= 0);
    CHECK(find(ev, nonzero_order, killed_at) < 0);
    CHECK(det.judged() == 0);
}

TEST_CASE("DirectionDetection: another client's command ends it Busy, leaving that client's thrust alone") {
    DetectionRig d;
    DirectionDetection& det = d.detection();
    std::optional<Result> end;
    det.run(":1.7", [&](const Result& r) { end = r; });
    REQUIRE(d.rig.run_until([&] { return det.pulsing() == 0; }, kRunGiveUpMs));
    const std::vector<int32_t> pilot{100, 0, 0, 0, 0, 0, 0, 200};
    REQUIRE(d.rig.vehicle().motors().set_thrust(pilot, ":1.9").ok());
    REQUIRE(d.rig.run_until([&] { return end.has_value(); }));
    CHECK(end->status == Status::Busy);
    CHECK(end->message.find("another command took over") != std::string::npos);
    d.rig.run_for(100);
    CHECK(d.rig.vehicle().readings().controller_client() == ":1.9");
    CHECK(d.rig.vehicle().readings().requested_values() == MotorValues{100, 0, 0, 0, 0, 0, 0, 200});
}

TEST_CASE("DirectionDetection: a vehicle that will not hold still ends it NotStill before any pulse") {
    // The timeout at its floor; the window 300 ms, not the rig's 100: under ASan beside other
    // tests the Teensy's yaw reading once stayed unchanged for a whole 100 ms window, which a
    // turning vehicle then matched as still (the pulse went out; CI's sanitize step, 7b540f0). A
    // still verdict stays possible from 900 ms (three windows) to the timeout.
    DetectionRig d("detect_settle_timeout_ms = 1000\n", "", 300);
    d.pool.turning = true;
    d.rig.wire().clear();
    const Result r = d.run();
    CHECK(r.status == Status::NotStill);
    CHECK(r.message == "the vehicle did not hold still within 1000 ms before thruster 0's pulse");
    CHECK(find(d.rig.wire().events(), nonzero_order) < 0);
    CHECK(d.detection().judged() == 0);
}

TEST_CASE("DirectionDetection: a stalled Teensy poll is no reading: a turning vehicle is not taken as still") {
    // The Teensy's frame held on the wire (a hung Teensy; teensy-link-lost only after
    // spi.silence_ms, here far beyond the test): its last reading stays in the telemetry and no
    // new one comes. Taken at each step as a sample, that value repeated made the turning vehicle
    // still and thruster 0 was pulsed (checked on the step-sampling code).
    DetectionRig d("detect_settle_timeout_ms = 1000\n", "silence_ms = 60000\n", 300);
    d.pool.turning = true;
    // Stalled once the Teensy has read the turning vehicle's yaw.
    const uint64_t read_before = d.rig.daemon().teensy().telemetry().orientation_read_ns;
    REQUIRE(d.rig.run_until([&] { return d.rig.daemon().teensy().telemetry().orientation_read_ns != read_before; }));
    d.rig.wire().clear();
    const Result r = [&] {
        StalledPoll stalled(d.teensy);
        return d.run();
    }();
    CHECK(r.status == Status::NotStill);
    CHECK(find(d.rig.wire().events(), nonzero_order) < 0);
    CHECK(d.detection().judged() == 0);
}

TEST_CASE("DirectionDetection: the Teensy falling silent or its poll stalling in a pulse ends it LinkError, its own zeros on the wire") {
    // teensy-link-lost (a kill, whose zeros would hide the detection's) only after
    // spi.silence_ms, here far beyond the test.
    DetectionRig d("", "silence_ms = 60000\n");
    DirectionDetection& det = d.detection();
    std::optional<Result> end;
    det.run(":1.7", [&](const Result& r) { end = r; });
    REQUIRE(d.rig.run_until([&] { return det.pulsing() == 0; }, kRunGiveUpMs));
    std::string message;
    SECTION("falling silent: its first unanswered frame takes it offline") {
        d.teensy.model([](sim::TeensyModel& m) { m.faults().inject_no_answer(1u << 30); });
        REQUIRE(d.rig.run_until([&] { return end.has_value(); }));
        message = "the Teensy went offline";
    }
    SECTION("a stalled poll (its frame held on the wire): no reading over the pulse's end to measure") {
        StalledPoll stalled(d.teensy);
        REQUIRE(d.rig.run_until([&] { return end.has_value(); }));
        message = "the Teensy gave no orientation reading over the end of thruster 0's pulse";
    }
    CHECK(end->status == Status::LinkError);
    CHECK(end->message == message);
    CHECK(det.judged() == 0);
    REQUIRE(d.rig.run_until([&] { return all_zero(d.rig.wire().events()); }));
    CHECK(d.rig.vehicle().readings().may_drive()); // not the kill's zeros
    CHECK(d.rig.vehicle().readings().requested_values() == MotorValues{});
}
