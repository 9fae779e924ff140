#include "core/packet.hpp"

namespace caracara {

std::string_view packet_field_name(std::size_t index) {
    static constexpr std::array<std::string_view, kPacketWords> names{
        "motor0", "motor1", "motor2", "motor3", "motor4", "motor5", "motor6",
        "motor7", "killState", "powerOffState", "red", "green", "blue"};
    return index < names.size() ? names[index] : std::string_view("?");
}

namespace {
PacketResult field_error(PacketError e, std::size_t index, int32_t value, std::string_view problem) {
    PacketResult r;
    r.error = e;
    r.field = static_cast<int>(index);
    r.message = "word " + std::to_string(index) + " (" + std::string(packet_field_name(index)) +
                "): " + std::string(problem) + ", got " + std::to_string(value);
    return r;
}
PacketResult decode_fields(std::span<const int32_t> words) {
    if (words.size() != kPacketWords) {
        PacketResult r;
        r.error = PacketError::WrongLength;
        r.message = "packet must be " + std::to_string(kPacketWords) + " int32 words, got " +
                    std::to_string(words.size());
        return r;
    }
    Packet p;
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        if (words[i] < -kMotorMax || words[i] > kMotorMax)
            return field_error(PacketError::MotorOutOfRange, i, words[i], "must be between -8850 and 8850");
        p.motors[i] = words[i];
    }
    p.kill_state = words[kPacketKill];
    p.kill = p.kill_state != 0;
    const int32_t off = words[kPacketPowerOff];
    if (off != 0 && off != 1)
        return field_error(PacketError::BadPowerOffState, kPacketPowerOff, off,
                           "must be 0 (stay on) or 1 (power off)");
    p.power_off = off == 1;
    uint8_t* colors[] = {&p.red, &p.green, &p.blue};
    for (std::size_t i = kPacketRed; i <= kPacketBlue; ++i) {
        if (words[i] < 0 || words[i] > 255)
            return field_error(PacketError::ColorOutOfRange, i, words[i], "must be between 0 and 255");
        *colors[i - kPacketRed] = static_cast<uint8_t>(words[i]);
    }
    PacketResult r;
    r.packet = p;
    return r;
}

} // namespace


PacketResult decode_packet(std::span<const int32_t> words) {
    PacketResult r = decode_fields(words);
    r.kill_requested = words.size() > kPacketKill && words[kPacketKill] != 0;
    return r;
}

namespace {
int32_t le_word(std::span<const uint8_t> bytes, std::size_t i) {
    return static_cast<int32_t>(uint32_t{bytes[4 * i]} | uint32_t{bytes[4 * i + 1]} << 8 |
                                uint32_t{bytes[4 * i + 2]} << 16 | uint32_t{bytes[4 * i + 3]} << 24);
}
} // namespace

PacketResult decode_packet_bytes(std::span<const uint8_t> bytes) {
    if (bytes.size() != kPacketBytes) {
        PacketResult r;
        r.error = PacketError::WrongLength;
        r.message = "packet must be " + std::to_string(kPacketBytes) + " bytes, got " + std::to_string(bytes.size());
        // As decode_packet: a torn packet that still carries killState keeps its kill.
        r.kill_requested = bytes.size() >= 4 * (kPacketKill + 1) && le_word(bytes, kPacketKill) != 0;
        return r;
    }
    std::array<int32_t, kPacketWords> words{};
    for (std::size_t i = 0; i < kPacketWords; ++i)
        words[i] = le_word(bytes, i);
    return decode_packet(words);
}

std::array<int32_t, kPacketWords> encode_packet(const Packet& p) {
    std::array<int32_t, kPacketWords> w{};
    for (std::size_t i = 0; i < kMotorCount; ++i)
        w[i] = p.motors[i];
    // kill_state keeps a caller's raw non-zero value; a bare kill flag becomes 1.
    w[kPacketKill] = p.kill ? (p.kill_state != 0 ? p.kill_state : 1) : 0;
    w[kPacketPowerOff] = p.power_off ? 1 : 0;
    w[kPacketRed] = p.red;
    w[kPacketGreen] = p.green;
    w[kPacketBlue] = p.blue;
    return w;
}

} // namespace caracara
