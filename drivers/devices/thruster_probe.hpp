// One probe of a bus scan: a plain status read (SeaBotix IDS 8.4: the read needs no register
// byte and changes nothing on the controller) of the longer, SeaBotix, length at one address,
// taken as a SeaBotix reply when it decodes as one, else as a legacy one (a legacy controller
// sends its four bytes, then the adapter reads idle bus), else as "something answered".
#pragma once

#include "core/thruster_config.hpp"
#include "drivers/platform/i2c_dev.hpp"
#include "drivers/platform/io_error.hpp"

#include <cstdint>
#include <optional>
#include <span>

namespace caracara {

struct ProbeAnswer {
    std::optional<Variant> variant; // nullopt: not a thruster's status reply
    uint8_t revision = 0;           // software revision from STATUS (SeaBotix bits 4-7, legacy 5-7)
};

// What a reply read from the device at `mt_write` says (pure: the unit tests feed it bytes).
ProbeAnswer classify_probe_reply(uint8_t mt_write, std::span<const uint8_t> reply);

// ONE I2C_RDWR with one read message. IoError::None with `out` set when the device ACKed;
// IoError::Nack when nobody is there; other errors as the adapter reports them.
IoError probe_thruster(I2cDev& bus, uint8_t mt_write, ProbeAnswer& out);

} // namespace caracara
