#include "daemon/vehicle/packet_handler.hpp"

#include "core/packet.hpp"
#include "core/status_of.hpp"
#include "daemon/vehicle/vehicle_condition.hpp"

#include <array>
#include <string>

namespace caracara {

Result PacketHandler::apply(std::span<const int32_t> words, std::string_view client) {
    PacketResult pr = decode_packet(words);
    // The packet's author asked for a kill: it happens even when another field is refused,
    // and the call still returns that field's error with nothing else changed.
    if (pr.kill_requested && !vehicle_.powered_off())
        vehicle_.kill(KillSource::Packet, "packet killState=" + std::to_string(words[kPacketKill]));
    if (!pr.ok())
        return {status_of(pr.error), pr.message};
    if (vehicle_.powered_off())
        return vehicle_.state_error();
    const Packet& p = pr.packet;
    if (p.kill) {
        // The seed: a non-zero killState stops the motors until a zero is sent. Kill first,
        // then a power-off the same packet asks for.
        if (p.power_off)
            return vehicle_.power_off(VehicleCondition::kPowerOffConfirmation);
        teensy_.set_leds(p.red, p.green, p.blue, nullptr);
        return {};
    }
    if (p.power_off)
        return vehicle_.power_off(VehicleCondition::kPowerOffConfirmation);
    if (vehicle_.readings().safety().state() == SafetyState::Killed) {
        if (vehicle_.readings().safety().kill_record().source != KillSource::Packet)
            return vehicle_.state_error();
        // killState 0 is the packet's "all clear": it clears a packet kill (arming follows).
        if (Result r = vehicle_.clear_packet_kill(); !r.ok())
            return r;
        teensy_.set_leds(p.red, p.green, p.blue, nullptr);
        return {};
    }
    if (Result r = vehicle_.motors().drive(p.motors, client); !r.ok())
        return r;
    if (teensy_.leds() != std::array<uint8_t, 3>{p.red, p.green, p.blue})
        teensy_.set_leds(p.red, p.green, p.blue, nullptr);
    return {};
}

void PacketHandler::apply(std::span<const int32_t> words, std::string_view client, Completion done) {
    const SafetyState before = vehicle_.readings().safety().state();
    Result r = apply(words, client);
    const SafetyState after = vehicle_.readings().safety().state();
    // An error too: a refused packet that carried a kill still killed, and its zeros go first.
    if (after != before && (after == SafetyState::Killed || after == SafetyState::PoweredOff))
        vehicle_.after_zeros(std::move(done), std::move(r));
    else
        done(r);
}

} // namespace caracara
