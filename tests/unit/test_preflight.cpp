// The preflight's table from the daemon's objects in process (DaemonRig on the fake seam): the
// items the e2e test cannot reach with the simulator (the recorder disabled, the Teensy not
// fitted, the built-in defaults, the clock), and that its window holds neither the loop nor the
// wire: the loop keeps ordering (zeros only) while it watches.
#include "daemon/commissioning/preflight.hpp"
#include "tests/catch.hpp"
#include "tests/unit/fakes/daemon_rig.hpp"

#include <map>
#include <optional>
#include <string>

using namespace caracara;
using namespace caracara::test;

namespace {

// Runs the preflight to its end: the rows by name.
std::map<std::string, PreflightRow> preflight(DaemonRig& rig) {
    std::optional<Result> result;
    rig.daemon().preflight().run([&](const Result& r) { result = r; });
    REQUIRE(!result); // replied later: the window runs on the loop
    REQUIRE(rig.run_until([&] { return result.has_value(); }, 10000));
    REQUIRE(result->ok());
    std::map<std::string, PreflightRow> rows;
    for (const PreflightRow& r : rig.daemon().preflight().rows())
        rows[r.name()] = r;
    return rows;
}

} // namespace

TEST_CASE("preflight on the fakes: the recorder disabled is the one no-go") {
    DaemonRig rig;
    rig.run_until_ready();
    rig.wire().clear();
    const auto rows = preflight(rig);
    REQUIRE(rows.size() == kMotorCount + 8);
    for (const auto& [name, row] : rows) {
        INFO(name << ": " << row.observed);
        CHECK(row.go == (name != "recorder"));
    }
    CHECK(rows.at("teensy").go);
    CHECK(rows.at("teensy").observed == "not fitted (spi.fitted = false)");
    CHECK(rows.at("config").go);
    CHECK(rows.at("config").observed == "built-in defaults (no file)");
    CHECK(rows.at("clock").go);
    CHECK(rows.at("clock").advice.empty());
    CHECK_FALSE(rows.at("recorder").go);
    CHECK(rows.at("recorder").observed == "disabled");
    CHECK(rows.at("recorder").advice == "set recorder.enabled = true to record the dive");
    CHECK_FALSE(rig.daemon().preflight().all_go());
    // The loop went on ordering through the window, and only zeros (nothing commanded).
    std::size_t orders = 0;
    for (const WireEvent& e : rig.wire().events())
        if (e.kind == WireEvent::Kind::Order) {
            ++orders;
            CHECK(e.value == 0);
        }
    CHECK(orders >= kMotorCount);
}

TEST_CASE("preflight: the kill switch pressed is no-go, the kill output read back as driven") {
    DaemonRig rig("arm_at_start = false\nloop_rate_hz = 50\n", "", true);
    rig.run_for(40);
    const auto rows = preflight(rig);
    CHECK_FALSE(rows.at("kill-switch").go);
    CHECK(rows.at("kill-switch").observed == "readable, pressed (kill)");
    CHECK(rows.at("kill-switch").advice == "release the kill switch");
    CHECK(rows.at("kill-output").go);
    CHECK(rows.at("kill-output").observed == "reads asserted (thrusters de-energized), as driven");
}

TEST_CASE("preflight: two callers at once both answered; a caller waiting when it stops gets Busy") {
    DaemonRig rig;
    int answered = 0;
    rig.daemon().preflight().run([&](const Result& r) { answered += r.ok(); });
    rig.daemon().preflight().run([&](const Result& r) { answered += r.ok(); });
    REQUIRE(rig.run_until([&] { return answered == 2; }, 10000));
    std::optional<Result> stopped;
    rig.daemon().preflight().run([&](const Result& r) { stopped = r; });
    rig.daemon().preflight().stop();
    REQUIRE(stopped);
    CHECK(stopped->status == Status::Busy);
}
