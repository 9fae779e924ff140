// The 13-word packet decoder (core/packet.hpp) fed arbitrary bytes: the input is the packet as
// it arrives, any length. Invariants: a packet is accepted exactly when every field is in its
// documented range; an accepted one re-encodes to the very words it came from; a refused one
// leaves the packet empty, names the bad field, and still reports a kill it carries.
#include "core/packet.hpp"
#include "fuzz/check.hpp"

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

using namespace caracara;

namespace {

// The documented ranges, written out again here rather than taken from the decoder.
int first_bad_field(std::span<const int32_t> w) {
    for (std::size_t i = 0; i < 8; ++i)
        if (w[i] < -8850 || w[i] > 8850)
            return static_cast<int>(i);
    if (w[9] != 0 && w[9] != 1)
        return 9;
    for (std::size_t i = 10; i < 13; ++i)
        if (w[i] < 0 || w[i] > 255)
            return static_cast<int>(i);
    return -1;
}

bool packet_empty(const Packet& p) {
    for (int32_t m : p.motors)
        if (m != 0)
            return false;
    return !p.kill && p.kill_state == 0 && !p.power_off && p.red == 0 && p.green == 0 && p.blue == 0;
}

void check_result(const PacketResult& r, std::span<const int32_t> w, std::size_t n_words) {
    FUZZ_CHECK(r.kill_requested == (n_words > kPacketKill && w[kPacketKill] != 0), "kill_requested wrong");
    if (n_words != kPacketWords) {
        FUZZ_CHECK(r.error == PacketError::WrongLength && r.field == -1, "a %zu-word packet was not WrongLength",
                   n_words);
        FUZZ_CHECK(packet_empty(r.packet) && !r.message.empty(), "refused packet not empty or unexplained");
        return;
    }
    const int bad = first_bad_field(w);
    if (bad < 0) {
        FUZZ_CHECK(r.ok(), "valid packet refused: %s", r.message.c_str());
        FUZZ_CHECK(r.message.empty(), "accepted packet carries a message");
        const auto again = encode_packet(r.packet);
        FUZZ_CHECK(std::memcmp(again.data(), w.data(), sizeof again) == 0, "encode(decode(w)) != w");
        FUZZ_CHECK(r.packet.kill == (w[kPacketKill] != 0) && r.packet.power_off == (w[kPacketPowerOff] == 1),
                   "kill/power-off flags wrong");
        return;
    }
    FUZZ_CHECK(!r.ok() && r.field == bad, "bad field %d reported as %d (%s)", bad, r.field,
               std::string(error_name(r.error)).c_str());
    FUZZ_CHECK(packet_empty(r.packet), "refused packet is not empty");
    FUZZ_CHECK(r.message.find("word " + std::to_string(bad) + " (" + std::string(packet_field_name(bad)) + ")") !=
                   std::string::npos,
               "message does not name the field: %s", r.message.c_str());
    const PacketError want = bad < 8 ? PacketError::MotorOutOfRange
                                     : bad == 9 ? PacketError::BadPowerOffState : PacketError::ColorOutOfRange;
    FUZZ_CHECK(r.error == want, "wrong error kind for field %d", bad);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::span<const uint8_t> bytes(data, size);
    // As little-endian int32 words (x86 and ARM both), whatever the length.
    std::vector<int32_t> words(size / 4);
    for (std::size_t i = 0; i < words.size(); ++i)
        words[i] = static_cast<int32_t>(uint32_t{data[4 * i]} | uint32_t{data[4 * i + 1]} << 8 |
                                        uint32_t{data[4 * i + 2]} << 16 | uint32_t{data[4 * i + 3]} << 24);

    const PacketResult from_bytes = decode_packet_bytes(bytes);
    if (size == kPacketBytes) {
        check_result(from_bytes, words, words.size());
    } else {
        FUZZ_CHECK(from_bytes.error == PacketError::WrongLength && packet_empty(from_bytes.packet),
                   "%zu bytes not refused as WrongLength", size);
        // The header's promise: a kill in a packet long enough to carry it is never lost.
        FUZZ_CHECK(from_bytes.kill_requested == (words.size() > kPacketKill && words[kPacketKill] != 0),
                   "a torn %zu-byte packet lost (or invented) its killState", size);
    }
    // The word decoder with whatever number of whole words the input holds.
    check_result(decode_packet(words), words, words.size());
    return 0;
}
