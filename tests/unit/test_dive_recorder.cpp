// daemon/dive/DiveRecorder (with its DiveSampler, CommissioningEvents and DiveWriter) on the
// daemon's objects over the fakes of the device seam (DaemonRig), the Teensy the simulator's model
// (FakeTeensyIo): the dive file a user reads back (core/dive_format's decode, as caracara-dive does)
// opens at the arming, holds a sample every cycle with what the pilot asked and the Teensy
// reported, an event for the kill with its source and reason, for each motor test and for each
// step of a direction detection (a PoolVehicle turned by the pulses), and closes at the kill, the
// power-off or the daemon stopping, ending on the zeros.
#include "daemon/dive/dive_recorder.hpp"

#include "core/dive_format.hpp"
#include "drivers/platform/dive_files.hpp"
#include "tests/catch.hpp"
#include "tests/unit/fakes/daemon_rig.hpp"
#include "tests/unit/fakes/fake_teensy_io.hpp"
#include "tests/unit/fakes/pool_vehicle.hpp"

#include <algorithm>
#include <array>
#include <filesystem>
#include <initializer_list>
#include <iterator>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

using namespace caracara;
using namespace caracara::test;

namespace {

// A direction detection's eight settles and pulses: a few seconds; the give-up far.
constexpr int kDetectionGiveUpMs = 30000;

struct TempDir {
    std::string path;
    TempDir() {
        char tmpl[] = "/tmp/caracara-dives-XXXXXX";
        if (!mkdtemp(tmpl))
            throw std::runtime_error("mkdtemp failed");
        path = tmpl;
    }
    ~TempDir() { std::filesystem::remove_all(path); }
};

// The recorder on, writing into `dir`.
std::string recorder(const TempDir& dir) {
    return "[recorder]\nenabled = true\ndirectory = \"" + dir.path + "\"\n";
}

// Every dive in `dir`, oldest first, as a user's reader decodes it.
std::vector<dive::Dive> dives(const TempDir& dir) {
    std::vector<dive::Dive> out;
    for (const DiveFile& f : list_dive_files(dir.path)) {
        std::vector<uint8_t> bytes;
        std::string error;
        if (read_whole_file(f.path, bytes, error))
            out.push_back(dive::decode(bytes));
    }
    return out;
}

// Until `n` dives are in `dir`, closed (their end record written).
bool closed(DaemonRig& rig, const TempDir& dir, std::size_t n) {
    return rig.run_until([&] {
        const auto d = dives(dir);
        return d.size() == n && std::all_of(d.begin(), d.end(), [](const dive::Dive& x) { return x.ended; });
    });
}

// Kills the vehicle (the dive's end) and returns its dive, the one in `dir`, read back whole.
dive::Dive killed_dive(DaemonRig& rig, const TempDir& dir) {
    REQUIRE(rig.vehicle().kill(KillSource::DBus, "test").ok());
    REQUIRE(closed(rig, dir, 1));
    const dive::Dive d = dives(dir).front();
    REQUIRE(d.ok());
    return d;
}

// The dive's events of these kinds, in order.
std::vector<dive::Event> events_of(const dive::Dive& d, std::initializer_list<dive::EventKind> kinds) {
    std::vector<dive::Event> out;
    std::copy_if(d.events.begin(), d.events.end(), std::back_inserter(out), [&](const dive::Event& e) {
        return std::find(kinds.begin(), kinds.end(), e.kind) != kinds.end();
    });
    return out;
}

const dive::Event* last_of(const dive::Dive& d, dive::EventKind kind) {
    const dive::Event* found = nullptr;
    for (const dive::Event& e : d.events)
        if (e.kind == kind)
            found = &e;
    return found;
}

std::array<int16_t, dive::kThrusters> values(std::initializer_list<int16_t> v) {
    std::array<int16_t, dive::kThrusters> a{};
    std::copy(v.begin(), v.end(), a.begin());
    return a;
}

} // namespace

TEST_CASE("DiveRecorder: armed at start, a dive; the pilot's thrust sampled; the kill its last event and its end") {
    TempDir dir;
    DaemonRig rig("loop_rate_hz = 50\n", recorder(dir));
    rig.run_until_ready();
    const std::vector<int32_t> pilot{100, -200, 300, 0, 0, 0, 0, 800};
    REQUIRE(rig.vehicle().motors().set_thrust(pilot, ":1.9").ok());
    REQUIRE(rig.run_until([&] { return rig.vehicle().readings().motor_values() == MotorValues{100, -200, 300, 0, 0, 0, 0, 800}; }));
    rig.run_for(100); // a few cycles at the pilot's values
    REQUIRE(rig.vehicle().kill(KillSource::DBus, "the pilot's kill").ok());
    REQUIRE(closed(rig, dir, 1));

    const dive::Dive d = dives(dir).front();
    REQUIRE(d.ok());
    CHECK(d.header.reason == "start");
    CHECK(d.header.loop_rate_hz == 50);
    CHECK(d.header.profile == "water");
    REQUIRE_FALSE(d.events.empty());
    CHECK(d.events.front().kind == dive::EventKind::State);
    CHECK(d.events.front().text == "start");
    // Samples: in time order, some at the pilot's values (asked and applied).
    REQUIRE(d.samples.size() >= 5);
    CHECK(std::is_sorted(d.samples.begin(), d.samples.end(),
                         [](const dive::Sample& a, const dive::Sample& b) { return a.t_100us < b.t_100us; }));
    const auto asked = values({100, -200, 300, 0, 0, 0, 0, 800});
    CHECK(std::any_of(d.samples.begin(), d.samples.end(),
                      [&](const dive::Sample& s) { return s.requested == asked && s.applied == asked; }));
    // The kill: its state, source and reason, and the dive's end named after it.
    const dive::Event* kill = last_of(d, dive::EventKind::State);
    REQUIRE(kill != nullptr);
    CHECK(kill->state == static_cast<uint8_t>(SafetyState::Killed));
    CHECK(kill->kill_source == static_cast<uint8_t>(KillSource::DBus));
    CHECK(kill->text == "the pilot's kill");
    CHECK(d.end.reason == "killed (" + std::string(name_of(KillSource::DBus)) + ")");
    // It ends on the zeros, the kill output asserted.
    const dive::Sample& last = d.samples.back();
    CHECK(last.requested == values({}));
    CHECK(last.applied == values({}));
    CHECK((last.flags & dive::kKillOutput) != 0);
    CHECK(last.t_100us <= d.end.t_100us);
}

TEST_CASE("DiveRecorder: killed, no dive is written; ClearKill opens the next, a power-off closes it") {
    TempDir dir;
    DaemonRig rig("loop_rate_hz = 50\narm_at_start = false\n", recorder(dir));
    rig.run_for(200);
    CHECK(dives(dir).empty());
    REQUIRE(rig.vehicle().clear_kill().ok());
    REQUIRE(rig.run_until([&] { return rig.vehicle().readings().may_drive(); }));
    rig.run_for(100);
    std::optional<Result> off;
    rig.vehicle().power_off("power-off", [&](const Result& r) { off = r; });
    REQUIRE(rig.run_until([&] { return off.has_value(); }));
    REQUIRE(closed(rig, dir, 1));
    const dive::Dive d = dives(dir).front();
    REQUIRE(d.ok());
    CHECK(d.header.reason == "clear-kill");
    CHECK(d.end.reason == "powered-off");
    CHECK(last_of(d, dive::EventKind::State)->state == static_cast<uint8_t>(SafetyState::PoweredOff));
}

TEST_CASE("DiveRecorder: a motor test starts and stops in the dive, with its thruster, value and caller") {
    TempDir dir;
    // The keep-alive at its floor: the test ends by itself in a few cycles.
    DaemonRig rig("loop_rate_hz = 50\ncommand_timeout_ms = 60000\n",
                  recorder(dir) + "[commissioning]\nmotor_test_keepalive_ms = 50\n");
    rig.run_until_ready();
    MotorTest& t = rig.daemon().motor_test();
    REQUIRE(t.run(2, 800, ":1.7").ok());
    REQUIRE(rig.run_until([&] { return t.active_thruster() < 0; })); // its keep-alive ran out
    rig.run_for(100);
    const dive::Dive d = killed_dive(rig, dir);
    const auto tests = events_of(d, {dive::EventKind::MotorTest});
    REQUIRE(tests.size() == 2);
    CHECK(tests[0].thruster == 2);
    CHECK(tests[0].value == dive::kOn);
    CHECK(tests[0].number == 800);
    CHECK(tests[0].client == ":1.7");
    CHECK(tests[1].thruster == 2);
    CHECK(tests[1].value == 0);
    CHECK(tests[1].t_100us >= tests[0].t_100us);
    // The samples between them carry thruster 2 at 800, the others at zero.
    CHECK(std::any_of(d.samples.begin(), d.samples.end(),
                      [](const dive::Sample& s) { return s.requested == values({0, 0, 800}); }));
}

TEST_CASE("DiveRecorder: the daemon stopping ends the dive 'stopped'; the Teensy's attitude is in its samples") {
    TempDir dir;
    FakeTeensyIo teensy(SpiSettings{}.device);
    teensy.set_attitude({0.5, -0.25, 0.125});
    {
        DaemonRig rig("loop_rate_hz = 50\n", recorder(dir) + "[spi]\nfitted = true\n", false, &teensy);
        rig.run_until_ready();
        REQUIRE(rig.run_until([&] { return rig.daemon().teensy().telemetry().orientation[2] != 0; }));
        rig.run_for(100);
    } // the daemon stops
    const auto all = dives(dir);
    REQUIRE(all.size() == 1);
    const dive::Dive& d = all.front();
    REQUIRE(d.ok());
    CHECK(d.ended);
    CHECK(d.end.reason == "stopped");
    const dive::Sample& last = d.samples.back();
    CHECK((last.flags & dive::kTeensyOnline) != 0);
    CHECK(last.orientation[0] == Approx(0.5).margin(1e-3));
    CHECK(last.orientation[1] == Approx(-0.25).margin(1e-3));
    CHECK(last.orientation[2] == Approx(0.125).margin(1e-3));
    CHECK(last.distances.size() == std::size_t(SpiSettings{}.teensy.limits.distance_sensor_count));
}

TEST_CASE("DiveRecorder: a direction detection in the dive: its start and end, each pulse on and off, each verdict") {
    TempDir dir;
    FakeTeensyIo teensy(SpiSettings{}.device);
    DaemonRig rig("loop_rate_hz = 100\n",
                  recorder(dir) + "[commissioning]\ndetect_pulse_ms = 300\ndetect_settle_ms = 100\n[spi]\nfitted = true\n", false, &teensy);
    PoolVehicle pool(rig, teensy);
    pool.mounting[2] = -1;
    rig.run_until_ready();
    REQUIRE(rig.run_until([&] { return rig.daemon().teensy().telemetry().online; }));
    std::optional<Result> end;
    rig.daemon().directions().run(":1.7", [&](const Result& r) { end = r; });
    REQUIRE(rig.run_until([&] { return end.has_value(); }, kDetectionGiveUpMs));
    REQUIRE(end->ok());
    rig.run_for(100);
    const dive::Dive d = killed_dive(rig, dir);
    const auto ev = events_of(d, {dive::EventKind::Detection, dive::EventKind::DetectionPulse,
                                  dive::EventKind::DetectionResult});
    // Started, then for each thruster: pulse on, pulse off, its verdict; then ended, 8 judged.
    REQUIRE(ev.size() == 2 + 3 * kMotorCount);
    CHECK(ev.front().kind == dive::EventKind::Detection);
    CHECK(ev.front().value == dive::kOn);
    CHECK(ev.front().client == ":1.7");
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        INFO("thruster " << i);
        const dive::Event& on = ev[1 + 3 * i];
        const dive::Event& off = ev[2 + 3 * i];
        const dive::Event& result = ev[3 + 3 * i];
        CHECK(on.kind == dive::EventKind::DetectionPulse);
        CHECK(on.thruster == i);
        CHECK(on.value == dive::kOn);
        CHECK(on.number == 3000);
        CHECK(off.kind == dive::EventKind::DetectionPulse);
        CHECK(off.thruster == i);
        CHECK(off.value == 0);
        CHECK(result.kind == dive::EventKind::DetectionResult);
        CHECK(result.thruster == i);
        CHECK(result.value == static_cast<uint32_t>(i == 2 ? DirectionVerdict::Reversed : DirectionVerdict::Ok));
        CHECK(result.t_100us >= on.t_100us);
    }
    CHECK(ev.back().kind == dive::EventKind::Detection);
    CHECK(ev.back().value == 0);
    CHECK(ev.back().number == kMotorCount);
}
