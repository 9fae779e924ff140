// The MCAP writer (tools/foxglove/mcap_writer.hpp), read back by a reader written here from the
// MCAP specification: the layout (magic, header, data section, Data End, summary, Summary
// Offsets, footer, magic), every CRC, the statistics, and that every index points where it
// says. The reference reader (@mcap/core) judges real exports in e2e_bridge. Also the channel
// catalogue shared with the bridge: every message's JSON has exactly its schema's fields.
#include "core/crc32.hpp"
#include "core/frames.hpp"
#include "tests/catch.hpp"
#include "tools/bridge/client_protocol.hpp"
#include "tools/bridge/command.hpp"
#include "core/safety_state.hpp"
#include "tools/foxglove/channels.hpp"
#include "tools/foxglove/dive_mcap.hpp"
#include "tools/foxglove/mcap_writer.hpp"

#include <array>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

using caracara::foxglove::McapWriter;
namespace fg = caracara::foxglove;

namespace {

struct Record {
    uint8_t op;
    std::size_t at;       // offset of the opcode
    std::size_t body;     // offset of the content
    uint64_t length;
};

struct Reader {
    const std::vector<uint8_t>& b;
    uint64_t u(std::size_t at, int n) const {
        uint64_t v = 0;
        for (int i = 0; i < n; ++i)
            v |= uint64_t{b.at(at + static_cast<std::size_t>(i))} << (8 * i);
        return v;
    }
    Record record(std::size_t at) const { return {b.at(at), at, at + 9, u(at + 1, 8)}; }
    std::string str(std::size_t& at) const {
        const auto n = static_cast<std::size_t>(u(at, 4));
        std::string s(b.begin() + static_cast<long>(at + 4), b.begin() + static_cast<long>(at + 4 + n));
        at += 4 + n;
        return s;
    }
};

const std::vector<uint8_t> kMagic = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};

uint32_t crc(const std::vector<uint8_t>& b, std::size_t from, std::size_t to) {
    return caracara::crc32(std::span<const uint8_t>(b.data() + from, to - from));
}

} // namespace

TEST_CASE("an MCAP file: layout, CRCs, statistics and indexes as the specification has them", "[mcap]") {
    McapWriter w("", "test", 200); // small chunks: several of them
    const uint16_t s = w.add_schema("caracara.Motors", "jsonschema", R"({"type":"object"})");
    const uint16_t a = w.add_channel(s, "/a", "json");
    const uint16_t c = w.add_channel(s, "/b", "json");
    CHECK(s == 1);
    CHECK(a == 1);
    CHECK(c == 2);
    for (uint64_t t = 0; t < 40; ++t)
        w.add_message(t % 3 ? a : c, 1000 + t, 1000 + t, R"({"applied":[1,2,3]})");
    CHECK(w.message_count() == 40);
    const std::vector<uint8_t> f = w.finish();
    const Reader r{f};

    REQUIRE(f.size() > 2 * kMagic.size());
    CHECK(std::vector<uint8_t>(f.begin(), f.begin() + 8) == kMagic);
    CHECK(std::vector<uint8_t>(f.end() - 8, f.end()) == kMagic);

    // The footer: opcode 0x02, 20 bytes of content, right before the closing magic.
    const std::size_t footer = f.size() - 8 - 29;
    const Record fr = r.record(footer);
    REQUIRE(fr.op == 0x02);
    REQUIRE(fr.length == 20);
    const std::size_t summary_start = r.u(fr.body, 8), offsets_start = r.u(fr.body + 8, 8);
    CHECK(r.u(fr.body + 16, 4) == crc(f, summary_start, footer + 9 + 16));

    // The data section: header first, records end to end up to Data End, whose CRC covers all before it.
    std::size_t at = 8;
    Record hr = r.record(at);
    CHECK(hr.op == 0x01);
    std::size_t chunks = 0;
    std::map<std::size_t, Record> by_offset;
    while (true) {
        const Record rec = r.record(at);
        by_offset[at] = rec;
        if (rec.op == 0x0F) {
            CHECK(r.u(rec.body, 4) == crc(f, 0, at));
            at = rec.body + rec.length;
            break;
        }
        if (rec.op == 0x06) {
            ++chunks;
            // Chunk: start, end, uncompressed size, CRC of the records, compression "", records.
            std::size_t p = rec.body + 28;
            CHECK(r.str(p).empty());
            const uint64_t size = r.u(p, 8);
            CHECK(size == r.u(rec.body + 16, 8));
            CHECK(r.u(rec.body + 24, 4) == crc(f, p + 8, p + 8 + size));
        }
        at = rec.body + rec.length;
        REQUIRE(at < f.size());
    }
    CHECK(chunks > 1);
    CHECK(at == summary_start);

    // The summary: groups of Schema, Channel, Statistics, Chunk Index, each named by a Summary Offset.
    std::map<uint8_t, std::pair<uint64_t, uint64_t>> groups;
    for (std::size_t p = offsets_start; p < footer;) {
        const Record rec = r.record(p);
        REQUIRE(rec.op == 0x0E);
        groups[f[rec.body]] = {r.u(rec.body + 1, 8), r.u(rec.body + 9, 8)};
        p = rec.body + rec.length;
    }
    CHECK(groups.size() == 4);
    for (const auto& [op, g] : groups)
        CHECK(r.record(g.first).op == op);
    const Record stats = r.record(groups.at(0x0B).first);
    CHECK(r.u(stats.body, 8) == 40);           // messages
    CHECK(r.u(stats.body + 8, 2) == 1);        // schemas
    CHECK(r.u(stats.body + 10, 4) == 2);       // channels
    CHECK(r.u(stats.body + 22, 4) == chunks);  // chunks
    CHECK(r.u(stats.body + 26, 8) == 1000);    // first time
    CHECK(r.u(stats.body + 34, 8) == 1039);    // last time

    // Every chunk index points at its chunk, and each message index entry at a message of its channel.
    std::size_t indexed = 0;
    for (std::size_t p = groups.at(0x08).first; p < groups.at(0x08).first + groups.at(0x08).second;) {
        const Record ci = r.record(p);
        REQUIRE(ci.op == 0x08);
        const std::size_t chunk_at = r.u(ci.body + 16, 8);
        const Record chunk = r.record(chunk_at);
        REQUIRE(chunk.op == 0x06);
        CHECK(r.u(ci.body + 24, 8) == 9 + chunk.length);
        const std::size_t records = chunk.body + 28 + 4 + 8; // after the empty compression string and size
        const std::size_t map_bytes = r.u(ci.body + 32, 4);
        for (std::size_t m = ci.body + 36; m < ci.body + 36 + map_bytes; m += 10) {
            const auto channel = static_cast<uint16_t>(r.u(m, 2));
            const Record mi = r.record(r.u(m + 2, 8));
            REQUIRE(mi.op == 0x07);
            CHECK(r.u(mi.body, 2) == channel);
            const std::size_t entries = r.u(mi.body + 2, 4) / 16;
            for (std::size_t e = 0; e < entries; ++e) {
                const Record msg = r.record(records + r.u(mi.body + 6 + e * 16 + 8, 8));
                REQUIRE(msg.op == 0x05);
                CHECK(r.u(msg.body, 2) == channel);
                CHECK(r.u(msg.body + 6, 8) == r.u(mi.body + 6 + e * 16, 8)); // the log time
                ++indexed;
            }
        }
        p = ci.body + ci.length;
    }
    CHECK(indexed == 40);
}

TEST_CASE("an MCAP file without messages is still whole", "[mcap]") {
    McapWriter w("", "test");
    w.add_channel(w.add_schema("x", "jsonschema", "{}"), "/x", "json");
    const std::vector<uint8_t> f = w.finish();
    CHECK(std::vector<uint8_t>(f.end() - 8, f.end()) == kMagic);
}

TEST_CASE("every channel's message has exactly its schema's fields", "[foxglove]") {
    std::map<fg::ChannelKind, std::string> sample = {
        {fg::ChannelKind::VehicleState, fg::to_json(fg::VehicleState{})},
        {fg::ChannelKind::Motors, fg::to_json(fg::Motors{})},
        {fg::ChannelKind::Thruster, fg::to_json(fg::Thruster{})},
        {fg::ChannelKind::Teensy, fg::to_json(fg::Teensy{})},
        {fg::ChannelKind::I2cBus, fg::to_json(fg::I2cBus{})},
        {fg::ChannelKind::Events, fg::to_json(fg::LogEvent{})},
        {fg::ChannelKind::Attitude, fg::attitude_json(0, 0, 0, 0)},
    };
    CHECK(fg::channels().size() == 14);
    for (const fg::ChannelInfo& c : fg::channels()) {
        const auto schema = nlohmann::json::parse(c.schema);
        const auto msg = nlohmann::json::parse(sample.at(c.kind));
        std::vector<std::string> fields, required;
        for (const auto& [k, _] : msg.items())
            fields.push_back(k);
        for (const auto& k : schema["required"])
            required.push_back(k);
        std::sort(required.begin(), required.end());
        INFO(c.topic);
        CHECK(fields == required);
    }
}

TEST_CASE("the state's failsafes as the daemon has them, the excluded thrusters from the exclude ones", "[foxglove]") {
    fg::VehicleState s;
    s.failsafes = {{"overtemp", "exclude", 2}, {"water-detect", "surface", 3}, {"stall", "exclude", 5}, {"pilot-lost", "kill", -1}};
    s.surfacing_ms = 1200;
    const auto j = nlohmann::json::parse(fg::to_json(s));
    CHECK(j["excluded"] == nlohmann::json::array({2, 5}));
    REQUIRE(j["failsafes"].size() == 4);
    CHECK(j["failsafes"][1] == nlohmann::json({{"condition", "water-detect"}, {"action", "surface"}, {"thruster", 3}}));
    CHECK(j["failsafes"][3]["thruster"] == -1);
    CHECK(j["surfacing_ms"] == 1200);
    const auto none = nlohmann::json::parse(fg::to_json(fg::VehicleState{}));
    CHECK(none["failsafes"].empty());
    CHECK(none["excluded"].empty());
    CHECK(none["surfacing_ms"] == -1);
    // The daemon's time left and pilot-lost persistence: none, or not known (a dive records neither).
    CHECK(none["ascent_left_ms"] == -1);
    CHECK(none["pilot_lost_left_ms"] == -1);
    CHECK(none["pilot_lost_ms"] == -1);
}

TEST_CASE("a dive exported to MCAP: the state's failsafes, excluded thrusters and surfacing follow its events", "[foxglove]") {
    namespace dive = caracara::dive;
    dive::Dive d;
    d.header.start_unix_ms = 1'700'000'000'000;
    d.header.profile = "water";
    for (uint32_t t : {0u, 1000u, 2000u, 3000u}) {
        dive::Sample s;
        s.t_100us = t;
        d.samples.push_back(s);
    }
    d.events = {{500, dive::EventKind::Failsafe, 0, 0, 3, dive::kFailsafeRaised, 0, "water-detect surface", ""},
                {600, dive::EventKind::Failsafe, 0, 0, 2, dive::kFailsafeRaised, 0, "overtemp exclude", ""},
                {2500, dive::EventKind::State, static_cast<uint8_t>(caracara::SafetyState::Killed),
                 static_cast<uint8_t>(caracara::KillSource::Failsafe), 0, 0, 0, "ascent done", ""},
                {2600, dive::EventKind::Failsafe, 0, 0, 2, 0, 0, "overtemp exclude", ""}};
    const std::vector<uint8_t> f = fg::dive_to_mcap(d);
    const std::string bytes(f.begin(), f.end()); // uncompressed: each message's JSON is in the file
    // 0.1 s in: both failsafes, thruster 2 excluded, the ascent 50 ms old (since its event at 50 ms).
    CHECK(bytes.find(R"("excluded":[2],"failsafes":[{"action":"surface","condition":"water-detect","thruster":3},)"
                     R"({"action":"exclude","condition":"overtemp","thruster":2}])") != std::string::npos);
    CHECK(bytes.find(R"("state":"arming","surfacing_ms":50})") != std::string::npos);
    // After the ascent's kill and overtemp cleared: water detect still holds, nothing excluded, not surfacing.
    CHECK(bytes.find(R"("excluded":[],"failsafes":[{"action":"surface","condition":"water-detect","thruster":3}],)"
                     R"("kill_source":"failsafe")") != std::string::npos);
    CHECK(bytes.find(R"("state":"killed","surfacing_ms":-1})") != std::string::npos);
    // The failsafe event's words: condition -> action, not "failsafe: " again after its name.
    CHECK(bytes.find(R"j("message":"water-detect -> surface (thruster 3)")j") != std::string::npos);
}

TEST_CASE("a dive exported to MCAP: motor tests and a detection run on /events", "[foxglove]") {
    namespace dive = caracara::dive;
    dive::Dive d;
    d.header.start_unix_ms = 1'700'000'000'000;
    dive::Sample s;
    d.samples = {s};
    d.events = {{100, dive::EventKind::MotorTest, 0, 0, 3, dive::kOn, 1500, "", ":1.4"},
                {200, dive::EventKind::MotorTest, 0, 0, 3, 0, 0, "", ""},
                {300, dive::EventKind::Detection, 0, 0, 0, dive::kOn, 0, "", ":1.4"},
                {400, dive::EventKind::DetectionPulse, 0, 0, 2, dive::kOn, 3000, "", ""},
                {500, dive::EventKind::DetectionResult, 0, 0, 2, 1, 1.8f, "yaw=-0.0180", ""},
                {600, dive::EventKind::Detection, 0, 0, 0, 0, 1, "", ""}};
    const std::vector<uint8_t> f = fg::dive_to_mcap(d);
    const std::string bytes(f.begin(), f.end());
    for (const char* m : {"motor test: thruster 3 at 1500", "motor test: thruster 3 stopped", "direction detection started",
                          "detection pulse: thruster 2 at 3000", "direction detection: thruster 2 reversed (yaw=-0.0180)",
                          "direction detection ended, 1 thrusters judged"}) {
        INFO(m);
        CHECK(bytes.find(std::string(R"("message":")") + m + "\"") != std::string::npos);
    }
}

namespace {
// A body-frame vector turned into the world by a /tf rotation.
std::array<double, 3> rotate(const nlohmann::json& q, std::array<double, 3> v) {
    const double x = q["x"], y = q["y"], z = q["z"], w = q["w"];
    // v + 2w (u x v) + 2 u x (u x v), u the quaternion's vector part
    const std::array<double, 3> t{2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])};
    return {v[0] + w * t[0] + (y * t[2] - z * t[1]), v[1] + w * t[1] + (z * t[0] - x * t[2]),
            v[2] + w * t[2] + (x * t[1] - y * t[0])};
}
nlohmann::json tf_rotation(double yaw, double pitch, double roll) {
    return nlohmann::json::parse(fg::attitude_json(0, yaw, pitch, roll))["rotation"];
}
} // namespace

TEST_CASE("/tf: the FLU body in the ENU world (core/frames), heading 0 facing north, a clockwise turn decreasing yaw", "[foxglove]") {
    const auto rest = rotate(tf_rotation(0, 0, 0), {1, 0, 0}); // forward points north: +y
    CHECK(rest[0] == Approx(0).margin(1e-9));
    CHECK(rest[1] == Approx(1));
    const auto east = rotate(tf_rotation(3.14159265358979 / 2, 0, 0), {1, 0, 0}); // heading 90 deg clockwise: east
    CHECK(east[0] == Approx(1));
    CHECK(east[1] == Approx(0).margin(1e-9));
    const auto yaw = [](const nlohmann::json& q) {
        return caracara::frames::yaw_of({q["x"], q["y"], q["z"], q["w"]});
    };
    CHECK(yaw(tf_rotation(0.3, 0, 0)) < yaw(tf_rotation(0, 0, 0)));
    CHECK(rotate(tf_rotation(0, 0.2, 0), {1, 0, 0})[2] > 0.19); // nose up: forward points up
    CHECK(rotate(tf_rotation(0, 0, 0.2), {0, 1, 0})[2] > 0.19); // roll right: the left side rises
}

TEST_CASE("/command/motion is a Twist in body FLU and /command/drive a pilot's words, both in the seed's axes for SetMotion", "[bridge]") {
    using caracara::bridge::CommandKind;
    using caracara::bridge::parse_command;
    const auto args = [](CommandKind k, const char* json) {
        const auto p = parse_command(k, json);
        INFO(p.error);
        REQUIRE(p.command);
        std::vector<double> out;
        for (const auto& a : p.command->args)
            out.push_back(std::get<double>(a));
        return out;
    };
    // SetMotion (x +port, y +forward, z +deeper, yaw +clockwise, pitch +nose up, roll +right side down).
    CHECK(args(CommandKind::Motion, R"({"linear":{"x":0.5}})") == std::vector<double>{0, 0.5, 0, 0, 0, 0});
    CHECK(args(CommandKind::Motion, R"({"linear":{"y":0.5}})") == std::vector<double>{0.5, 0, 0, 0, 0, 0});
    CHECK(args(CommandKind::Motion, R"({"linear":{"z":0.5}})") == std::vector<double>{0, 0, -0.5, 0, 0, 0});
    CHECK(args(CommandKind::Motion, R"({"angular":{"z":0.5}})") == std::vector<double>{0, 0, 0, -0.5, 0, 0});
    CHECK(args(CommandKind::Motion, R"({"angular":{"y":0.5}})") == std::vector<double>{0, 0, 0, 0, -0.5, 0});
    CHECK(args(CommandKind::Motion, R"({"angular":{"x":0.5}})") == std::vector<double>{0, 0, 0, 0, 0, 0.5});
    CHECK(args(CommandKind::Motion, R"({"linear":{"x":0,"y":0,"z":0},"angular":{"x":0,"y":0,"z":0}})") ==
          std::vector<double>(6, 0.0));
    CHECK(args(CommandKind::Drive, R"({"forward":0.5})") == std::vector<double>{0, 0.5, 0, 0, 0, 0});
    CHECK(args(CommandKind::Drive, R"({"starboard":0.5})") == std::vector<double>{-0.5, 0, 0, 0, 0, 0});
    CHECK(args(CommandKind::Drive, R"({"up":0.5})") == std::vector<double>{0, 0, -0.5, 0, 0, 0});
    CHECK(args(CommandKind::Drive, R"({"turn_right":0.5,"nose_up":0.25,"roll_right":-1})") ==
          std::vector<double>{0, 0, 0, 0.5, 0.25, -1});
    // The old flat fields are refused by name, never read as forward; anything else named.
    for (const char* old : {R"({"x":0.5})", R"({"y":0.1})", R"({"yaw":-1})", R"({"linear":{"x":0.1},"roll":0})"}) {
        const auto p = parse_command(CommandKind::Motion, old);
        CHECK_FALSE(p.command);
        CHECK(p.error.find("motion is a Twist in body FLU") != std::string::npos);
        CHECK(p.error.find("of the seed's axes is refused") != std::string::npos);
    }
    CHECK(parse_command(CommandKind::Motion, R"({"linear":{"x":"fast"}})").error == "motion linear 'x' must be a number");
    CHECK(parse_command(CommandKind::Motion, R"({"linear":[1,0,0]})").error.find("must be an object") != std::string::npos);
    CHECK(parse_command(CommandKind::Motion, R"({"linear":{"w":1}})").error == "motion's 'linear' takes x, y, z, not 'w'");
    CHECK(parse_command(CommandKind::Motion, R"({"twist":{}})").error == "motion takes \"linear\" and \"angular\", not 'twist'");
    CHECK(parse_command(CommandKind::Drive, R"({"surge":1})").error ==
          "drive takes forward, starboard, up, turn_right, nose_up, roll_right, not 'surge'");
    CHECK(parse_command(CommandKind::Drive, R"({"forward":true})").error == "drive 'forward' must be a number");
    CHECK(caracara::bridge::command_topic("/command/drive") == CommandKind::Drive);
}

TEST_CASE("the bridge's client protocol: commands only from advertised command topics, errors named", "[bridge]") {
    using caracara::bridge::ClientProtocol;
    ClientProtocol p(fg::channels().size());
    auto binary = [](uint32_t id, std::string body) {
        // Sized first: GCC 12's -Warray-bounds misjudges an insert after a 5-byte initializer list.
        std::vector<uint8_t> b(5 + body.size());
        b[0] = 1;
        for (std::size_t i = 0; i < 4; ++i)
            b[1 + i] = uint8_t(id >> (8 * i));
        std::copy(body.begin(), body.end(), b.begin() + 5);
        return b;
    };
    CHECK_FALSE(p.on_binary(binary(5, R"({"linear":{"x":0.5}})")).command); // not advertised
    CHECK(p.on_text(R"({"op":"advertise","channels":[{"id":5,"topic":"/command/motion","encoding":"json"}]})").replies.empty());
    const auto o = p.on_binary(binary(5, R"({"linear":{"y":0.5},"angular":{"z":1}})"));
    REQUIRE(o.command);
    REQUIRE(o.command->args.size() == 6);
    CHECK(std::get<double>(o.command->args[0]) == 0.5);  // left: the seed's +x (port)
    CHECK(std::get<double>(o.command->args[3]) == -1);   // counter-clockwise: the seed's -yaw
    CHECK(std::get<double>(o.command->args[1]) == 0); // an axis left out
    CHECK_FALSE(p.on_binary(binary(5, R"({"linear":{"x":"fast"}})")).command);
    const auto old = p.on_binary(binary(5, R"({"x":0.5})"));
    CHECK_FALSE(old.command);
    CHECK(old.replies.at(0).find("/command/motion: motion is a Twist in body FLU") != std::string::npos);
    CHECK_FALSE(p.on_binary(binary(5, "{")).command);
    CHECK(p.on_text(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":1},{"id":1,"channelId":2}]})").replies.size() == 1);
    CHECK(p.subscribers(1) == std::vector<uint32_t>{1});
    CHECK(p.on_text(R"({"op":"unsubscribe","subscriptionIds":[1]})").replies.empty());
    CHECK(p.subscribers(1).empty());
    CHECK(p.on_text(R"({"op":"getParameters"})").replies.size() == 1);
    // The commissioning commands: a motor test's (thruster, value), detection without arguments.
    CHECK(p.on_text(R"({"op":"advertise","channels":[{"id":6,"topic":"/command/motor_test","encoding":"json"},)"
                    R"({"id":7,"topic":"/command/detect_directions","encoding":"json"}]})").replies.empty());
    const auto test = p.on_binary(binary(6, R"({"thruster":3,"value":-800})"));
    REQUIRE(test.command);
    CHECK(test.command->kind == caracara::bridge::CommandKind::MotorTest);
    CHECK(test.command->args == std::vector<caracara::bridge::CommandArg>{int32_t{3}, int32_t{-800}});
    const auto missing = p.on_binary(binary(6, R"({"thruster":3})"));
    CHECK_FALSE(missing.command);
    CHECK(missing.replies.at(0).find("/command/motor_test: motor_test needs 'value': an integer") != std::string::npos);
    CHECK_FALSE(p.on_binary(binary(6, R"({"thruster":3,"value":1e12})")).command);
    const auto detect = p.on_binary(binary(7, "{}"));
    REQUIRE(detect.command);
    CHECK(detect.command->args.empty());
    CHECK(caracara::bridge::command_spec(caracara::bridge::CommandKind::DetectDirections).reply ==
          caracara::bridge::CommandReply::Directions);
}
