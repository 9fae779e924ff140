// The bus scan's judgement (core/bus_scan_report) and its reading of a probe's reply
// (drivers/devices/thruster_probe): what is probed, ok / missing / moved / wrong variant /
// unexpected, and a reply told SeaBotix from legacy by its own bytes.
#include "core/bus_scan_report.hpp"
#include "drivers/devices/thruster_probe.hpp"
#include "drivers/protocol/seabotix.hpp"

#include "tests/catch.hpp"

#include <array>
#include <vector>

using namespace caracara;

namespace {

ThrusterConfig at(uint8_t mt, uint8_t channel, Variant v = Variant::SeaBotix) {
    ThrusterConfig t;
    t.mt = mt;
    t.variant = v;
    t.mux = MuxRoute{0x70, channel};
    return t;
}

ScanDevice found(uint8_t mt, uint8_t channel, Variant v = Variant::SeaBotix) {
    return {MuxRoute{0x70, channel}, mt, v, 0, -1};
}

} // namespace

TEST_CASE("the scan probes the IDS's two addresses and the configured ones on the trunk and four channels") {
    const std::vector<ThrusterConfig> cfg{at(0x56, 0), at(0x56, 1)};
    CHECK(scan_addresses(cfg) == std::vector<uint8_t>{0x52, 0x54, 0x56});
    const auto segments = scan_segments(cfg);
    REQUIRE(segments.size() == 5);
    CHECK(!segments[0]);
    CHECK(segment_text(segments[4]) == "mux 0x70 channel 3");
    CHECK(scan_segments(std::vector<ThrusterConfig>{ThrusterConfig{}}).size() == 1); // no mux: the trunk alone
}

TEST_CASE("each thruster where configured is ok and the bus matches") {
    const std::vector<ThrusterConfig> cfg{at(0x52, 0), at(0x56, 1)};
    BusScanReport r;
    r.devices = {found(0x56, 1), found(0x52, 0)};
    judge_bus_scan(cfg, r);
    CHECK(r.thrusters[0].verdict == ScanVerdict::Ok);
    CHECK(r.thrusters[1].verdict == ScanVerdict::Ok);
    CHECK(r.devices[0].thruster == 1);
    CHECK(r.matches());
}

TEST_CASE("missing, moved, wrong variant and unexpected, each with what to do") {
    const std::vector<ThrusterConfig> cfg{at(0x52, 0), at(0x56, 0), at(0x58, 1), at(0x5A, 1)};
    BusScanReport r;
    r.devices = {found(0x52, 0), found(0x58, 2), found(0x5A, 1, Variant::Legacy), found(0x54, 3, Variant::Legacy)};
    judge_bus_scan(cfg, r);
    CHECK(r.thrusters[0].verdict == ScanVerdict::Ok);
    CHECK(r.thrusters[1].verdict == ScanVerdict::Missing);
    CHECK(r.thrusters[1].advice.find("cable") != std::string::npos);
    CHECK(r.thrusters[2].verdict == ScanVerdict::Moved);
    CHECK(r.thrusters[2].advice.find("mux 0x70 channel 2") != std::string::npos);
    CHECK(r.thrusters[3].verdict == ScanVerdict::WrongVariant);
    CHECK(r.thrusters[3].advice.find("legacy") != std::string::npos);
    CHECK(r.devices[3].thruster == -1);
    CHECK_FALSE(r.matches());
}

TEST_CASE("a thruster readdressed on its own channel is moved; two strangers there leave it missing") {
    const std::vector<ThrusterConfig> cfg{at(0x5C, 2)};
    BusScanReport r;
    r.devices = {found(0x60, 2)};
    judge_bus_scan(cfg, r);
    CHECK(r.thrusters[0].verdict == ScanVerdict::Moved);
    r.devices = {found(0x60, 2), found(0x62, 2)};
    judge_bus_scan(cfg, r);
    CHECK(r.thrusters[0].verdict == ScanVerdict::Missing);
    CHECK(r.devices[0].thruster == -1);
}

TEST_CASE("a moved thruster does not take the place of one where configured") {
    // Thruster 0 configured on channel 0 at 0x52 and there; 0x52 also answers on channel 1.
    const std::vector<ThrusterConfig> cfg{at(0x52, 1), at(0x52, 0)};
    BusScanReport r;
    r.devices = {found(0x52, 0), found(0x52, 3)};
    judge_bus_scan(cfg, r);
    CHECK(r.thrusters[1].verdict == ScanVerdict::Ok);
    CHECK(r.thrusters[0].verdict == ScanVerdict::Moved);
    CHECK(r.thrusters[0].device == 1);
}

TEST_CASE("a trunk device answers on every channel too: counted once, on the trunk") {
    BusScanReport r;
    CHECK(add_scan_device(r, {std::nullopt, 0x52, Variant::SeaBotix, 0, -1}));
    CHECK_FALSE(add_scan_device(r, found(0x52, 1)));
    CHECK(add_scan_device(r, found(0x56, 1)));
    REQUIRE(r.devices.size() == 2);
    ThrusterConfig trunk;
    judge_bus_scan(std::vector<ThrusterConfig>{trunk, at(0x56, 1)}, r);
    CHECK(r.matches());
}

TEST_CASE("a probe's reply: SeaBotix by its 7 bytes, legacy by its 4, else no thruster") {
    const auto sb = encode_seabotix_status(0x52, 0x32, 0, 0, 0x80, 20); // revision 3, brushless
    ProbeAnswer a = classify_probe_reply(0x52, sb);
    CHECK(a.variant == Variant::SeaBotix);
    CHECK(a.revision == 3);
    const auto lg = encode_legacy_status(0x54, 0x40, 0); // code 2: brushed, legacy
    std::array<uint8_t, 7> rx{};
    rx.fill(0xFF); // a legacy controller stops after 4 bytes; the adapter reads idle bus
    std::copy(lg.begin(), lg.end(), rx.begin());
    a = classify_probe_reply(0x54, rx);
    CHECK(a.variant == Variant::Legacy);
    CHECK(a.revision == 2);
    CHECK_FALSE(classify_probe_reply(0x56, sb).variant); // another address's reply: not its status
    rx.fill(0xFF);
    CHECK_FALSE(classify_probe_reply(0x54, rx).variant);
}
