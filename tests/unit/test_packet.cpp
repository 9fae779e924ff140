#include "core/packet.hpp"

#include "tests/catch.hpp"
#include <limits>
#include <vector>

using namespace caracara;

namespace {
using Words = std::array<int32_t, kPacketWords>;

Words valid_words() { return Words{100, -200, 300, -400, 8850, -8850, 0, 1, 0, 0, 255, 128, 0}; }
} // namespace

TEST_CASE("a valid packet decodes every field") {
    const PacketResult r = decode_packet(valid_words());
    REQUIRE(r.ok());
    CHECK(r.field == -1);
    CHECK(r.packet.motors == MotorValues{100, -200, 300, -400, 8850, -8850, 0, 1});
    CHECK_FALSE(r.packet.kill);
    CHECK_FALSE(r.packet.power_off);
    CHECK(r.packet.red == 255);
    CHECK(r.packet.green == 128);
    CHECK(r.packet.blue == 0);
}

TEST_CASE("killState: zero is all clear, any non-zero value kills") {
    Words w = valid_words();
    for (int32_t k : {1, -1, 42, std::numeric_limits<int32_t>::max(), std::numeric_limits<int32_t>::min()}) {
        w[kPacketKill] = k;
        const PacketResult r = decode_packet(w);
        REQUIRE(r.ok());
        CHECK(r.packet.kill);
        CHECK(r.packet.kill_state == k);
    }
    w[kPacketKill] = 0;
    CHECK_FALSE(decode_packet(w).packet.kill);
}

TEST_CASE("powerOffState: 1 initiates power off, 0 does not, anything else is refused") {
    Words w = valid_words();
    w[kPacketPowerOff] = 1;
    PacketResult r = decode_packet(w);
    REQUIRE(r.ok());
    CHECK(r.packet.power_off);
    for (int32_t bad : {2, -1, 255, std::numeric_limits<int32_t>::min()}) {
        w[kPacketPowerOff] = bad;
        r = decode_packet(w);
        CHECK(r.error == PacketError::BadPowerOffState);
        CHECK(error_name(r.error) == "BadPowerOffState");
        CHECK(r.field == 9);
        CHECK_THAT(r.message, Catch::Contains("word 9") && Catch::Contains("powerOffState") &&
                                  Catch::Contains(std::to_string(bad)));
        CHECK_FALSE(r.packet.power_off);
    }
}

TEST_CASE("every motor outside -8850..8850 is refused by index and name") {
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        for (int32_t bad : {8851, -8851, std::numeric_limits<int32_t>::max()}) {
            Words w = valid_words();
            w[i] = bad;
            const PacketResult r = decode_packet(w);
            CHECK(r.error == PacketError::MotorOutOfRange);
            CHECK(r.field == static_cast<int>(i));
            CHECK_THAT(r.message, Catch::Contains("word " + std::to_string(i)) &&
                                      Catch::Contains("motor" + std::to_string(i)));
            CHECK(r.packet.motors == MotorValues{});  // a bad packet changes nothing
        }
    }
}

TEST_CASE("every colour outside 0..255 is refused by index and name") {
    const char* names[] = {"red", "green", "blue"};
    for (std::size_t i = kPacketRed; i <= kPacketBlue; ++i) {
        for (int32_t bad : {-1, 256, 1000}) {
            Words w = valid_words();
            w[i] = bad;
            const PacketResult r = decode_packet(w);
            CHECK(r.error == PacketError::ColorOutOfRange);
            CHECK(r.field == static_cast<int>(i));
            CHECK_THAT(r.message, Catch::Contains(names[i - kPacketRed]) && Catch::Contains(std::to_string(bad)));
            CHECK(r.packet.red == 0);
            CHECK(r.packet.motors == MotorValues{});
        }
    }
}

TEST_CASE("a packet of the wrong length is refused") {
    for (std::size_t n : {0u, 12u, 14u}) {
        std::vector<int32_t> w(n, 0);
        const PacketResult r = decode_packet(w);
        CHECK(r.error == PacketError::WrongLength);
        CHECK(error_name(r.error) == "WrongLength");
        CHECK(r.field == -1);
    }
    std::vector<uint8_t> bytes(51, 0);
    CHECK(decode_packet_bytes(bytes).error == PacketError::WrongLength);
}

TEST_CASE("raw bytes decode as little-endian int32 words") {
    std::array<uint8_t, kPacketBytes> b{};
    // motor0 = -8850 = 0xFFFFDD6E, motor7 = 8850 = 0x00002292, killState = 1, blue = 255
    b[0] = 0x6E; b[1] = 0xDD; b[2] = 0xFF; b[3] = 0xFF;
    b[28] = 0x92; b[29] = 0x22;
    b[32] = 0x01;
    b[48] = 0xFF;
    const PacketResult r = decode_packet_bytes(b);
    REQUIRE(r.ok());
    CHECK(r.packet.motors[0] == -8850);
    CHECK(r.packet.motors[7] == 8850);
    CHECK(r.packet.kill);
    CHECK(r.packet.blue == 255);
    b[36] = 0x02;  // powerOffState = 2
    CHECK(decode_packet_bytes(b).error == PacketError::BadPowerOffState);
}

TEST_CASE("encode and decode round-trip") {
    const Words w = valid_words();
    const PacketResult r = decode_packet(w);
    REQUIRE(r.ok());
    CHECK(encode_packet(r.packet) == w);
    Packet p;
    p.kill = true;
    CHECK(encode_packet(p)[kPacketKill] == 1);
    CHECK(packet_field_name(8) == "killState");
    CHECK(packet_field_name(13) == "?");
}

TEST_CASE("a kill in a packet is seen even when another field is refused") {
    std::array<int32_t, kPacketWords> w{};
    w[kPacketKill] = 1;
    w[0] = 9000; // out of range
    PacketResult r = decode_packet(w);
    CHECK(r.error == PacketError::MotorOutOfRange);
    CHECK(r.kill_requested);
    w[0] = 0;
    w[kPacketRed] = 300;
    CHECK(decode_packet(w).kill_requested);
    w[kPacketRed] = 0;
    w[kPacketPowerOff] = 2;
    CHECK(decode_packet(w).kill_requested);
    // A short packet that still carries killState.
    CHECK(decode_packet(std::span<const int32_t>(w.data(), 9)).kill_requested);
    CHECK_FALSE(decode_packet(std::span<const int32_t>(w.data(), 8)).kill_requested);
    w[kPacketKill] = 0;
    CHECK_FALSE(decode_packet(w).kill_requested);
}

TEST_CASE("a torn byte packet that carries killState keeps its kill (fuzz_packet regression)") {
    std::vector<uint8_t> b(36, 0);
    b[32] = 0x05;  // killState = 5, the packet cut after word 8
    PacketResult r = decode_packet_bytes(b);
    CHECK(r.error == PacketError::WrongLength);
    CHECK(r.kill_requested);
    b.push_back(0);  // 37 bytes: not whole words, the kill is still there
    CHECK(decode_packet_bytes(b).kill_requested);
    b.resize(35);  // killState cut short: nothing to read
    CHECK_FALSE(decode_packet_bytes(b).kill_requested);
    b.assign(36, 0);
    CHECK_FALSE(decode_packet_bytes(b).kill_requested);
}
