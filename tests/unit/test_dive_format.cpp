// The dive file format (core/dive_format.hpp, docs/dive-format.md): what the recorder writes
// reads back the same; every cut and every flipped bit of a file is refused with its problem
// named at an offset; the layout is the documented one (a reader in another language can
// follow docs/dive-format.md byte by byte).
#include "core/config.hpp"
#include "core/crc32.hpp"
#include "core/dive_format.hpp"
#include "tests/catch.hpp"

#include <string>
#include <vector>

using namespace caracara;

namespace {

dive::Dive sample_dive() {
    dive::Dive d;
    d.header = {1700000000123ull, 42, 50, "water", "clear-kill"};
    for (uint32_t k = 0; k < 120; ++k) {
        dive::Sample s;
        s.t_100us = k * 200;
        s.requested[2] = static_cast<int16_t>(k * 10);
        s.applied[2] = static_cast<int16_t>(k * 9);
        s.budget_limit = 7850;
        s.flags = dive::kTeensyOnline | (k > 100 ? dive::kKillSwitch : 0) | (1u << dive::kBusStateShift);
        s.thrusters[2] = {static_cast<int16_t>(-k), 31, 40, static_cast<uint8_t>(k > 60 ? 1 : 0),
                          dive::kOnline | dive::kStatusKnown | dive::kCurrentKnown, k, 2, 3};
        s.orientation = {0.5f, -0.25f, 0.125f};
        s.distances = {1000, 1200};
        s.bus_errors = 4;
        d.samples.push_back(s);
    }
    d.events.push_back({0, dive::EventKind::State, 0, 0, 0, 0, 0, "clear-kill", ":1.7"});
    d.events.push_back({12200, dive::EventKind::Fault, 0, 0, 2, 1, 0, "overtemp", ""});
    d.events.push_back({20000, dive::EventKind::BusRestored, 0, 0, 0, 4, 22.5f, "", ""});
    d.events.push_back({23800, dive::EventKind::State, 2, 2, 0, 0, 0, "kill switch set", ""});
    d.ended = true;
    d.end = {23800, "killed (switch)"};
    return d;
}

// Two blocks, as the recorder writes them about a second apart, records in time order.
std::vector<uint8_t> encode(const dive::Dive& d) {
    std::vector<uint8_t> out = dive::encode_header(d.header);
    std::vector<uint8_t> blocks[2];
    std::size_t e = 0;
    for (std::size_t k = 0; k < d.samples.size(); ++k) {
        auto& r = blocks[k < 60 ? 0 : 1];
        for (; e < d.events.size() && d.events[e].t_100us <= d.samples[k].t_100us; ++e)
            dive::encode_event(r, d.events[e]);
        dive::encode_sample(r, d.samples[k]);
    }
    for (; e < d.events.size(); ++e)
        dive::encode_event(blocks[1], d.events[e]);
    dive::encode_end(blocks[1], d.end);
    for (const auto& r : blocks) {
        const auto blk = dive::seal_block(r);
        out.insert(out.end(), blk.begin(), blk.end());
    }
    return out;
}

} // namespace

TEST_CASE("crc32 is zlib's") {
    const std::string s = "123456789";
    CHECK(crc32(std::span(reinterpret_cast<const uint8_t*>(s.data()), s.size())) == 0xCBF43926u);
    // Eight bytes at a time and the rest one by one: every length and alignment agrees with
    // the bit-by-bit definition.
    std::vector<uint8_t> bytes(300);
    for (std::size_t i = 0; i < bytes.size(); ++i)
        bytes[i] = static_cast<uint8_t>(i * 131 + 7);
    for (std::size_t from = 0; from < 9; ++from)
        for (std::size_t len = 0; from + len <= bytes.size(); len += 7) {
            uint32_t c = 0xFFFFFFFFu;
            for (std::size_t i = from; i < from + len; ++i) {
                c ^= bytes[i];
                for (int k = 0; k < 8; ++k)
                    c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
            }
            CHECK(crc32(std::span<const uint8_t>(bytes).subspan(from, len)) == (c ^ 0xFFFFFFFFu));
        }
}

TEST_CASE("a dive reads back as written") {
    const dive::Dive d = sample_dive();
    const std::vector<uint8_t> file = encode(d);
    const dive::Dive r = dive::decode(file);
    REQUIRE(r.ok());
    CHECK(r.header.start_unix_ms == d.header.start_unix_ms);
    CHECK(r.header.loop_rate_hz == 50);
    CHECK(r.header.profile == "water");
    CHECK(r.samples == d.samples);
    CHECK(r.events == d.events);
    CHECK(r.ended);
    CHECK(r.end == d.end);
    CHECK(r.samples[0].bus_state() == 1);
}

TEST_CASE("the largest sample (every thruster, every distance, extreme values) reads back whole") {
    // The sample is written on the stack with room for exactly the format's largest record: a
    // wrong bound would drop it (or cut it), and this dive would not read back.
    dive::Dive d;
    d.header = {1, 2, 50, "water", "clear-kill"};
    dive::Sample s;
    s.t_100us = UINT32_MAX;
    s.requested.fill(INT16_MAX);
    s.applied.fill(INT16_MIN + 1);
    s.budget_limit = INT16_MAX;
    s.flags = static_cast<uint8_t>(dive::kSaturated | dive::kKillSwitch | dive::kTeensyOnline | dive::kKillOutput |
                                   (2u << dive::kBusStateShift)); // bus lost, the last state
    for (auto& t : s.thrusters)
        t = {INT16_MIN, 0xFF, 0xFF, 0x1F, 0xFF, UINT32_MAX, UINT32_MAX, UINT32_MAX}; // every FAULT bit
    s.orientation = {-1e30f, 1e30f, 3.5f};
    s.distances.assign(dive::kMaxDistances, 0xFFFF);
    s.bus_errors = UINT32_MAX;
    s.bus_recoveries = UINT32_MAX;
    d.samples = {s, s};
    d.ended = true;
    d.end = {UINT32_MAX, "killed (dbus)"};
    const dive::Dive r = dive::decode(encode(d));
    REQUIRE(r.ok());
    REQUIRE(r.samples.size() == 2);
    CHECK(r.samples[1] == s);
}

TEST_CASE("the documented layout: magic, version, little-endian fields, block header") {
    const auto h = dive::encode_header({0x0102030405060708ull, 0, 50, "", ""});
    CHECK(std::string(h.begin(), h.begin() + 8) == "CARADIVE");
    CHECK(h[8] == 1);  // version 1, little-endian
    CHECK(h[9] == 0);
    CHECK(h[10] == 24); // fields: u64 u64 u32 u16+0 u16+0
    CHECK(h[12] == 0x08);
    std::vector<uint8_t> r;
    dive::encode_sample(r, {});
    CHECK(r[0] == 1);
    CHECK(r[1] + 256 * r[2] == 4 + 16 + 16 + 2 + 1 + 8 * 18 + 12 + 8 + 1); // 204 bytes
    const auto b = dive::seal_block(r);
    CHECK(std::string(b.begin(), b.begin() + 4) == "DBLK");
    CHECK(b.size() == r.size() + 12);
}

TEST_CASE("every cut of a dive is refused as truncated, never read as more") {
    const dive::Dive d = sample_dive();
    std::vector<uint8_t> file = dive::encode_header(d.header);
    std::vector<uint8_t> rec;
    for (const auto& s : d.samples)
        dive::encode_sample(rec, s);
    dive::encode_end(rec, d.end);
    const auto blk = dive::seal_block(rec);
    file.insert(file.end(), blk.begin(), blk.end());
    REQUIRE(dive::decode(file).ok());
    const std::size_t header = file.size() - blk.size();
    for (std::size_t n = 0; n < file.size(); n += 7) {
        const dive::Dive r = dive::decode(std::span(file).first(n));
        if (n == header) {
            CHECK(r.ok()); // a dive whose first block never came: a header and nothing else
            CHECK(!r.ended);
            continue;
        }
        REQUIRE(!r.ok());
        CHECK((r.error == dive::ReadError::Truncated || r.error == dive::ReadError::NotADive));
        CHECK(r.samples.empty());
        CHECK(r.message.find(" at byte ") != std::string::npos);
    }
}

TEST_CASE("a flipped bit anywhere is refused by the checksums or the magic") {
    const std::vector<uint8_t> file = encode(sample_dive());
    REQUIRE(dive::decode(file).ok());
    for (std::size_t i = 0; i < file.size(); i += 3) {
        std::vector<uint8_t> bad = file;
        bad[i] ^= 0x10;
        const dive::Dive r = dive::decode(bad);
        INFO("byte " << i);
        CHECK(!r.ok());
        CHECK(r.error_offset <= i);
    }
}

TEST_CASE("another version is refused by name") {
    std::vector<uint8_t> file = encode(sample_dive());
    file[8] = 2;
    const dive::Dive r = dive::decode(file);
    CHECK(r.error == dive::ReadError::Version);
    CHECK(r.message.find("format version 2") != std::string::npos);
}

TEST_CASE("[recorder] configuration") {
    const ConfigResult def = parse_config_string("");
    REQUIRE(def.ok());
    CHECK(def.config->recorder.enabled);
    CHECK(def.config->recorder.directory == "/var/log/caracara");
    CHECK(def.config->recorder.max_total_mb == 256);
    const ConfigResult r =
        parse_config_string("[recorder]\nenabled = false\ndirectory = \"/srv/dives\"\nmax_total_mb = 10\n");
    REQUIRE(r.ok());
    CHECK(!r.config->recorder.enabled);
    CHECK(r.config->recorder.directory == "/srv/dives");
    const ConfigResult bad = parse_config_string("[recorder]\ndirectory = \"dives\"\nmax_total_mb = 0\nsize = 1\n");
    REQUIRE(!bad.ok());
    CHECK(bad.error().find("recorder.directory: must be an absolute path") != std::string::npos);
    CHECK(bad.error().find("recorder.max_total_mb") != std::string::npos);
    CHECK(bad.error().find("unknown key 'recorder.size'") != std::string::npos);
}

TEST_CASE("a failsafe event and the failsafe kill source read back; a kind beyond them is refused") {
    dive::Dive d = sample_dive();
    d.events.insert(d.events.end() - 1,
                    {23700, dive::EventKind::Failsafe, 0, 0, 3, dive::kFailsafeRaised, 0, "water-detect surface", ""});
    d.events.insert(d.events.end() - 1,
                    {23750, dive::EventKind::Failsafe, 0, 0, 0, dive::kFailsafeRaised | dive::kFailsafeVehicle, 0,
                     "bus-lost kill", ""});
    d.events.back().kill_source = static_cast<uint8_t>(KillSource::Failsafe);
    const dive::Dive r = dive::decode(encode(d));
    REQUIRE(r.ok());
    CHECK(r.events == d.events);
    CHECK(dive::event_kind_name(r.events[4].kind) == "failsafe");

    // One past the last kind: refused by name, what came before kept.
    std::vector<uint8_t> records;
    dive::Event bad = d.events[4];
    dive::encode_event(records, bad);
    records[1 + 2 + 4] = static_cast<uint8_t>(dive::EventKind::DetectionResult) + 1; // kind, after the record header and t
    std::vector<uint8_t> file = dive::encode_header(d.header);
    const auto blk = dive::seal_block(records);
    file.insert(file.end(), blk.begin(), blk.end());
    CHECK_FALSE(dive::decode(file).ok());
}

// One dive's worth of commissioning events before the kill at 23800.
void add_commissioning(dive::Dive& d) {
    const std::vector<dive::Event> c = {
        {21000, dive::EventKind::MotorTest, 0, 0, 3, dive::kOn, 1500, "", ":1.9"},
        {21500, dive::EventKind::MotorTest, 0, 0, 3, 0, 0, "", ""},
        {22000, dive::EventKind::Detection, 0, 0, 0, dive::kOn, 0, "", ":1.9"},
        {22100, dive::EventKind::DetectionPulse, 0, 0, 0, dive::kOn, 3000, "", ""},
        {22900, dive::EventKind::DetectionPulse, 0, 0, 0, 0, 0, "", ""},
        {22900, dive::EventKind::DetectionResult, 0, 0, 0, 1, 1.9f, "yaw=-0.0190 pitch=+0.0000 roll=-0.0010 along=-0.0190", ""},
        {23800, dive::EventKind::Detection, 0, 0, 0, 0, 1, "", ""},
    };
    d.events.insert(d.events.end() - 1, c.begin(), c.end());
}

TEST_CASE("motor test and direction detection events read back; a verdict out of range is refused") {
    dive::Dive d = sample_dive();
    add_commissioning(d);
    const dive::Dive r = dive::decode(encode(d));
    REQUIRE(r.ok());
    CHECK(r.events == d.events);
    CHECK(dive::event_kind_name(r.events[3].kind) == "motor-test");
    CHECK(dive::event_kind_name(r.events[5].kind) == "detection");
    CHECK(dive::event_kind_name(r.events[6].kind) == "detection-pulse");
    CHECK(dive::event_kind_name(r.events[8].kind) == "detection-result");

    dive::Dive bad = sample_dive();
    add_commissioning(bad);
    bad.events[8].value = 3; // beyond inconclusive
    const dive::Dive rb = dive::decode(encode(bad));
    CHECK_FALSE(rb.ok());
    CHECK(rb.error == dive::ReadError::Malformed);
    CHECK(rb.message.find("event record") != std::string::npos);
}
