#include "drivers/devices/thruster_probe.hpp"

#include "drivers/protocol/seabotix.hpp"

#include <array>

namespace caracara {

ProbeAnswer classify_probe_reply(uint8_t mt_write, std::span<const uint8_t> reply) {
    for (const VariantFormat& format : kVariantFormats) {
        const Variant v = format.variant;
        if (reply.size() < status_length(v))
            continue;
        const DecodedStatus d = decode_status(v, mt_write, reply.first(status_length(v)));
        if (!d.ok())
            continue;
        const uint8_t revision = d.status.firmware_revision;
        return {v, revision};
    }
    return {};
}

IoError probe_thruster(I2cDev& bus, uint8_t mt_write, ProbeAnswer& out) {
    std::array<uint8_t, kMaxStatusLength> rx{};
    const IoError e = bus.read(mt_addr7(mt_write), rx);
    if (e == IoError::None)
        out = classify_probe_reply(mt_write, rx);
    return e;
}

} // namespace caracara
