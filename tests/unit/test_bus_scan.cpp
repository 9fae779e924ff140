// daemon/commissioning/BusScan on the daemon's objects over the fakes of the device seam
// (DaemonRig): refused unless killed, touching nothing; killed, every configured thruster found
// where the configuration puts it; a thruster that does not answer is missing, the others ok;
// a second scan while one runs is Busy; ClearKill during a scan ends it.
#include "daemon/commissioning/bus_scan.hpp"

#include "tests/catch.hpp"
#include "tests/unit/fakes/daemon_rig.hpp"

#include <cerrno>
#include <string>
#include <optional>

using namespace caracara;
using namespace caracara::test;

namespace {

// Runs a scan to its end: its result.
Result scan(DaemonRig& rig) {
    std::optional<Result> result;
    rig.daemon().bus_scan().run([&](const Result& r) { result = r; });
    REQUIRE(rig.run_until([&] { return result.has_value(); }, 10000));
    return *result;
}

} // namespace

TEST_CASE("BusScan: refused unless the vehicle is killed, its report left empty") {
    DaemonRig rig;
    rig.run_until_ready();
    rig.wire().clear();
    const Result r = scan(rig);
    CHECK(r.status == Status::NotKilled);
    CHECK(r.message.find("ready") != std::string::npos);
    CHECK(rig.daemon().bus_scan().report().devices.empty());
    CHECK_FALSE(rig.daemon().bus_scan().running());
    CHECK(rig.vehicle().readings().state_name() == "ready");
}

TEST_CASE("BusScan: killed, each configured thruster is found at its address, the bus matches") {
    DaemonRig rig;
    rig.run_until_ready();
    REQUIRE(rig.vehicle().kill(KillSource::DBus, "test").ok());
    rig.run_for(20);
    REQUIRE(scan(rig).ok());
    const BusScanReport& report = rig.daemon().bus_scan().report();
    const auto& thrusters = rig.config().thrusters;
    REQUIRE(report.thrusters.size() == thrusters.size());
    for (std::size_t i = 0; i < thrusters.size(); ++i) {
        INFO("thruster " << i);
        CHECK(report.thrusters[i].verdict == ScanVerdict::Ok);
    }
    REQUIRE(report.devices.size() == thrusters.size());
    for (const ScanDevice& d : report.devices) {
        REQUIRE(d.thruster >= 0);
        CHECK(d.mt == thrusters[static_cast<std::size_t>(d.thruster)].mt);
        CHECK(d.variant.has_value());
    }
    CHECK(report.matches());
    CHECK(rig.vehicle().readings().state_name() == "killed"); // a scan does not arm
}

TEST_CASE("BusScan: a thruster that does not answer is missing, the others ok") {
    DaemonRig rig;
    rig.run_until_ready();
    rig.wire().fail(3, ENXIO); // a NACK: nobody at its address
    // Its unreachable kill first (a kill during a scan ends it), then the scan.
    REQUIRE(rig.run_until([&] { return rig.vehicle().readings().kill_source_name() == "device"; }));
    rig.run_for(50);
    const Result r = scan(rig);
    INFO(r.message);
    REQUIRE(r.ok());
    const BusScanReport& report = rig.daemon().bus_scan().report();
    for (std::size_t i = 0; i < report.thrusters.size(); ++i) {
        INFO("thruster " << i);
        CHECK(report.thrusters[i].verdict == (i == 3 ? ScanVerdict::Missing : ScanVerdict::Ok));
        CHECK_FALSE(report.thrusters[i].advice.empty() == (i == 3));
    }
    CHECK_FALSE(report.matches());
}

TEST_CASE("BusScan: a second scan while one runs is Busy; ClearKill during a scan ends it") {
    DaemonRig rig;
    rig.run_until_ready();
    REQUIRE(rig.vehicle().kill(KillSource::DBus, "test").ok());
    rig.run_for(20);
    std::optional<Result> first, second;
    rig.daemon().bus_scan().run([&](const Result& r) { first = r; });
    rig.daemon().bus_scan().run([&](const Result& r) { second = r; });
    REQUIRE(second.has_value());
    CHECK(second->status == Status::Busy);
    REQUIRE(rig.run_until([&] { return first.has_value(); }, 10000));
    CHECK(first->ok());

    std::optional<Result> ended;
    rig.daemon().bus_scan().run([&](const Result& r) { ended = r; });
    REQUIRE(rig.daemon().bus_scan().running());
    REQUIRE(rig.vehicle().clear_kill().ok());
    REQUIRE(rig.run_until([&] { return ended.has_value(); }, 10000));
    CHECK(ended->status == Status::NotKilled);
    CHECK_FALSE(rig.daemon().bus_scan().running());
}
