// The legacy packet (ApplyPacket, "Caracara USB packet format"): one call that may kill, power
// off, clear a packet kill, drive and set the LEDs. It reads the packet and asks the Vehicle,
// which keeps the motor and state policy, for each of those in the seed's order (the LEDs the
// TeensyPort).
#pragma once

#include "core/status.hpp"
#include "daemon/loop/completion.hpp"
#include "daemon/teensy/teensy_port.hpp"
#include "daemon/vehicle/vehicle.hpp"

#include <cstdint>
#include <span>
#include <string_view>

namespace caracara {

class PacketHandler {
public:
    PacketHandler(Vehicle& vehicle, TeensyPort& teensy) : vehicle_(vehicle), teensy_(teensy) {}
    // `done` once the zeros a killing or powering-off packet put on the bus are on the wire (as
    // Vehicle::kill); a packet that neither kills nor powers off is done at once.
    void apply(std::span<const int32_t> words, std::string_view client, Completion done);

private:
    Result apply(std::span<const int32_t> words, std::string_view client);

    Vehicle& vehicle_;
    TeensyPort& teensy_;
};

} // namespace caracara
