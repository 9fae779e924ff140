#include "drivers/protocol/seabotix.hpp"

namespace caracara {

std::optional<uint8_t> motor_to_speed(int32_t value) {
    // Range check first: negating INT32_MIN below would be undefined.
    if (value < -kMotorMax || value > kMotorMax)
        return std::nullopt;
    const int32_t magnitude = value < 0 ? -value : value;
    // Integer round-half-up of a non-negative quotient. 102 * |v| is even and 8850 / 2 = 4425
    // is odd, so an exact half never occurs and the direction of tie-breaking cannot matter.
    const int32_t steps = (magnitude * kSpeedSteps + kMotorMax / 2) / kMotorMax;
    if (steps == 0)
        return kSpeedStop;
    if (value > 0)
        return static_cast<uint8_t>(0x80 + steps);
    return static_cast<uint8_t>(0x7F - steps);
}

std::optional<int32_t> speed_to_steps(uint8_t speed) {
    if (speed < kSpeedMin || speed > kSpeedMax)
        return std::nullopt;
    if (speed >= 0x80)
        return static_cast<int32_t>(speed) - 0x80;
    return -(0x7F - static_cast<int32_t>(speed));
}

std::optional<int32_t> speed_to_motor(uint8_t speed) {
    const auto steps = speed_to_steps(speed);
    if (!steps)
        return std::nullopt;
    const int32_t magnitude_steps = *steps < 0 ? -*steps : *steps;
    // Same rounding as motor_to_speed. 8850 * s is even and 102 / 2 = 51 is odd: no ties.
    const int32_t magnitude = (magnitude_steps * kMotorMax + kSpeedSteps / 2) / kSpeedSteps;
    return *steps < 0 ? -magnitude : magnitude;
}

uint8_t checksum8(std::span<const uint8_t> bytes) {
    unsigned sum = 0;
    for (uint8_t b : bytes)
        sum += b;
    return static_cast<uint8_t>(sum & 0xFFu);
}

std::optional<OrderBytes> encode_order(uint8_t mt_write, uint8_t speed, uint8_t info) {
    if (!is_valid_mt(mt_write) || speed < kSpeedMin || speed > kSpeedMax)
        return std::nullopt;
    // The address byte is on the wire but not in our buffer (the kernel sends it), yet the
    // IDS checksum covers it: MT + SPEED + INFO.
    const std::array<uint8_t, 3> covered{mt_write, speed, info};
    return OrderBytes{speed, info, checksum8(covered)};
}

DecodedOrder decode_order(uint8_t mt_write, std::span<const uint8_t> bytes) {
    DecodedOrder out;
    if (bytes.size() != kOrderLength) {
        out.error = CodecError::BadLength;
        return out;
    }
    const std::array<uint8_t, 3> covered{mt_write, bytes[0], bytes[1]};
    if (checksum8(covered) != bytes[2]) {
        out.error = CodecError::BadChecksum;
        return out;
    }
    out.speed = bytes[0];
    out.info = bytes[1];
    if (bytes[0] < kSpeedMin || bytes[0] > kSpeedMax)
        out.error = CodecError::BadSpeed;
    return out;
}

std::string format_faults(FaultSet faults) {
    std::string out;
    for (Fault f : kAllFaults) {
        if (!faults.has(f))
            continue;
        if (!out.empty())
            out += ',';
        out += fault_name(f);
    }
    return out;
}

bool fault_stops_motor(Variant v, Fault f) {
    // SeaBotix 8.4.2 remark 2: water detect is a warning, the motor keeps running.
    if (f == Fault::WaterDetect)
        return v == Variant::Legacy;
    return true;
}

bool fault_latches_until_power_cycle(Variant v, Fault f) {
    switch (f) {
    case Fault::GroundFault: return true;
    case Fault::WaterDetect: return v == Variant::Legacy;
    case Fault::Overtemp:
    case Fault::Stall:
    case Fault::Hall: return false;
    }
    return false;
}

bool faults_stop_motor(Variant v, FaultSet faults) {
    for (Fault f : kAllFaults)
        if (faults.has(f) && fault_stops_motor(v, f))
            return true;
    return false;
}

namespace {

LegacySoftware legacy_software_from_code(uint8_t code) {
    switch (code) {
    case 0: return LegacySoftware::Original;
    case 1: return LegacySoftware::AveoxBrushless;
    case 2: return LegacySoftware::LegacyBrushed;
    case 4: return LegacySoftware::BrushedRev4;
    default: return LegacySoftware::Unknown;
    }
}

SeaBotixStatus decode_seabotix_fields(std::span<const uint8_t> r) {
    SeaBotixStatus s;
    s.status = r[1];
    s.fault = r[2];
    s.current = r[3];
    s.speed = r[4];
    s.temperature = r[5];
    s.firmware_revision = static_cast<uint8_t>(s.status >> 4);
    s.brushless = (s.status & 0x02) != 0;
    s.non_current_limiting = (s.status & 0x01) != 0;
    s.reserved_status_bits = static_cast<uint8_t>((s.status >> 2) & 0x03);
    s.faults = fault_set_from_bits(s.fault);
    s.reserved_fault_bits = static_cast<uint8_t>(s.fault >> 5);
    if (s.brushless)
        s.current_deciamps = s.current;
    s.speed_motor = speed_to_motor(s.speed);
    s.temperature_c = s.temperature;
    return s;
}

LegacyStatus decode_legacy_fields(std::span<const uint8_t> r) {
    LegacyStatus s;
    s.status = r[1];
    s.max_power = r[2];
    s.revision_code = static_cast<uint8_t>(s.status >> 5);
    s.software = legacy_software_from_code(s.revision_code);
    // Bits 0-3 (overtemp, stall, hall, ground fault) and bit 4 (water detect) line up with Fault.
    s.faults = fault_set_from_bits(s.status);
    switch (s.software) {
    case LegacySoftware::AveoxBrushless:
        s.max_power_meaning = MaxPowerMeaning::CurrentDeciAmps;
        s.current_deciamps = s.max_power;
        break;
    case LegacySoftware::LegacyBrushed:
    case LegacySoftware::BrushedRev4:
        s.max_power_meaning = MaxPowerMeaning::PowerSpeed;
        s.power_motor = speed_to_motor(s.max_power);
        break;
    case LegacySoftware::Original:
    case LegacySoftware::Unknown:
        s.max_power_meaning = MaxPowerMeaning::Unknown;
        break;
    }
    return s;
}

} // namespace

DecodedStatus decode_status(Variant v, uint8_t mt_write, std::span<const uint8_t> reply) {
    DecodedStatus out;
    out.status.variant = v;
    const std::size_t n = status_length(v);
    if (reply.size() != n) {
        out.error = CodecError::BadLength;
        return out;
    }
    // First byte before checksum: a reply from the wrong device (or an idle-high bus reading
    // 0xFF) is reported as such even when its checksum happens to be right too.
    if (reply[0] != mt_read(mt_write)) {
        out.error = CodecError::BadFirstByte;
        return out;
    }
    if (checksum8(reply.first(n - 1)) != reply[n - 1]) {
        out.error = CodecError::BadChecksum;
        return out;
    }
    ThrusterStatus& st = out.status;
    switch (v) {
    case Variant::SeaBotix:
        st.seabotix = decode_seabotix_fields(reply);
        st.faults = st.seabotix.faults;
        st.current_deciamps = st.seabotix.current_deciamps;
        st.temperature_c = st.seabotix.temperature_c;
        st.speed_motor = st.seabotix.speed_motor;
        st.actual_speed = st.seabotix.speed;
        st.firmware_revision = st.seabotix.firmware_revision;
        break;
    case Variant::Legacy:
        st.legacy = decode_legacy_fields(reply);
        st.faults = st.legacy.faults;
        st.current_deciamps = st.legacy.current_deciamps;
        if (st.legacy.max_power_meaning == MaxPowerMeaning::PowerSpeed)
            st.actual_speed = st.legacy.max_power;
        st.firmware_revision = st.legacy.revision_code;
        break;
    }
    return out;
}

std::array<uint8_t, 7> encode_seabotix_status(uint8_t mt_write, uint8_t status, uint8_t fault,
                                              uint8_t current, uint8_t speed, uint8_t temperature) {
    std::array<uint8_t, 7> r{mt_read(mt_write), status, fault, current, speed, temperature, 0};
    r[6] = checksum8(std::span<const uint8_t>(r).first(6));
    return r;
}

std::array<uint8_t, 4> encode_legacy_status(uint8_t mt_write, uint8_t status, uint8_t max_power) {
    std::array<uint8_t, 4> r{mt_read(mt_write), status, max_power, 0};
    r[3] = checksum8(std::span<const uint8_t>(r).first(3));
    return r;
}

} // namespace caracara
