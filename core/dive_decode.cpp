// The dive file's reading side. Every length is checked against what is left before it is
// used, every enum and float against its range, so a truncated, corrupt or hostile file gives
// a named error at a byte offset and everything read before it, never a crash (fuzz_dive).
#include "core/byte_reader.hpp"
#include "core/crc32.hpp"
#include "core/dive_format.hpp"

#include <cmath>
#include <string>

namespace caracara::dive {

namespace {

constexpr uint8_t kMaxSafetyState = 3;  // SafetyState::PoweredOff
constexpr uint8_t kMaxKillSource = 7;   // KillSource::Failsafe
constexpr unsigned kMaxBusState = 2;    // BusState::Lost
constexpr uint8_t kFaultBits = 0x1F;
constexpr std::size_t kBlockHeader = 12;

bool read_sample(ByteReader& r, Sample& s) {
    s.t_100us = r.u32();
    for (int16_t& v : s.requested)
        v = r.i16();
    for (int16_t& v : s.applied)
        v = r.i16();
    s.budget_limit = r.i16();
    s.flags = r.u8();
    for (ThrusterSample& t : s.thrusters) {
        t.speed = r.i16();
        t.current_da = r.u8();
        t.temperature_c = r.u8();
        t.faults = r.u8();
        t.flags = r.u8();
        t.nacks = r.u32();
        t.bad_replies = r.u32();
        t.errors = r.u32();
        if (t.faults & ~kFaultBits)
            return false;
    }
    for (float& v : s.orientation)
        v = r.f32(); // NaN too: whatever the Teensy sent
    s.bus_errors = r.u32();
    s.bus_recoveries = r.u32();
    const std::size_t n = r.u8();
    if (n > kMaxDistances)
        return false;
    s.distances.resize(r.failed() ? 0 : n);
    for (uint16_t& d : s.distances)
        d = r.u16();
    return !r.failed() && s.bus_state() <= kMaxBusState;
}

bool read_event(ByteReader& r, Event& e) {
    e.t_100us = r.u32();
    const uint8_t kind = r.u8();
    e.state = r.u8();
    e.kill_source = r.u8();
    e.thruster = r.u8();
    e.value = r.u32();
    e.number = r.f32();
    e.text = r.str(kMaxText);
    e.client = r.str(kMaxText);
    if (r.failed() || kind < 1 || kind > static_cast<uint8_t>(EventKind::DetectionResult))
        return false;
    e.kind = static_cast<EventKind>(kind);
    if (e.kind == EventKind::DetectionResult && e.value > kMaxVerdict)
        return false;
    return e.state <= kMaxSafetyState && e.kill_source <= kMaxKillSource && e.thruster < kThrusters &&
           std::isfinite(e.number);
}

class Decoder {
public:
    Decoder(std::span<const uint8_t> bytes, Dive& d) : bytes_(bytes), d_(d) {}

    void run() {
        if (!header())
            return;
        std::size_t at = header_end_;
        while (at < bytes_.size() && !d_.ended) {
            if (!block(at))
                return;
        }
        if (at < bytes_.size())
            fail(ReadError::Malformed, at, "data after the end record");
    }

private:
    bool fail(ReadError e, std::size_t at, const std::string& what) {
        d_.error = e;
        d_.error_offset = at;
        d_.message = std::string(read_error_name(e)) + " at byte " + std::to_string(at) + ": " + what;
        return false;
    }

    bool header() {
        const std::size_t fixed = kMagic.size() + 4;
        if (bytes_.size() < kMagic.size() ||
            std::string_view(reinterpret_cast<const char*>(bytes_.data()), kMagic.size()) != kMagic)
            return fail(ReadError::NotADive, 0, "the file does not start with \"CARADIVE\"");
        ByteReader r(bytes_.subspan(kMagic.size()));
        const uint16_t version = r.u16();
        const uint16_t len = r.u16();
        if (r.failed())
            return fail(ReadError::Truncated, kMagic.size(), "the file ends inside the header");
        if (version != kVersion)
            return fail(ReadError::Version, kMagic.size(),
                        "format version " + std::to_string(version) + " (this reader knows " +
                            std::to_string(kVersion) + ")");
        if (bytes_.size() - fixed < std::size_t(len) + 4)
            return fail(ReadError::Truncated, fixed, "the file ends inside the header");
        const auto fields = bytes_.subspan(fixed, len);
        ByteReader c(bytes_.subspan(fixed + len, 4));
        if (crc32(fields) != c.u32())
            return fail(ReadError::Checksum, fixed, "the header's CRC-32 does not match");
        ByteReader f(fields);
        Header& h = d_.header;
        h.start_unix_ms = f.u64();
        h.start_mono_ns = f.u64();
        h.loop_rate_hz = f.u32();
        h.profile = f.str(kMaxText);
        h.reason = f.str(kMaxText);
        if (f.failed() || f.left() != 0)
            return fail(ReadError::Malformed, fixed, "the header's fields do not fill its length");
        header_end_ = fixed + len + 4;
        return true;
    }

    bool block(std::size_t& at) {
        const std::size_t left = bytes_.size() - at;
        if (left < kBlockHeader)
            return fail(ReadError::Truncated, at,
                        "the file ends inside a block header (" + std::to_string(left) + " bytes left)");
        if (std::string_view(reinterpret_cast<const char*>(bytes_.data() + at), 4) != kBlockMagic)
            return fail(ReadError::Malformed, at, "no block starts here (expected \"DBLK\")");
        ByteReader r(bytes_.subspan(at + 4, 8));
        const uint32_t len = r.u32();
        const uint32_t crc = r.u32();
        if (len > kMaxBlockBytes)
            return fail(ReadError::Malformed, at, "a block of " + std::to_string(len) + " bytes (at most " +
                                                      std::to_string(kMaxBlockBytes) + ")");
        if (left - kBlockHeader < len)
            return fail(ReadError::Truncated, at,
                        "the file ends inside a block of " + std::to_string(len) + " bytes (" +
                            std::to_string(left - kBlockHeader) + " left)");
        const auto records = bytes_.subspan(at + kBlockHeader, len);
        if (crc32(records) != crc)
            return fail(ReadError::Checksum, at, "the CRC-32 of a block of " + std::to_string(len) + " bytes does not match");
        if (!parse_records(records, at + kBlockHeader))
            return false;
        at += kBlockHeader + len;
        return true;
    }

    bool parse_records(std::span<const uint8_t> records, std::size_t base) {
        ByteReader r(records);
        while (r.left() > 0) {
            const std::size_t rec_at = base + r.pos();
            if (d_.ended)
                return fail(ReadError::Malformed, rec_at, "a record after the end record");
            const uint8_t kind = r.u8();
            const uint16_t len = r.u16();
            if (r.failed() || len > r.left())
                return fail(ReadError::Malformed, rec_at, "a record longer than its block");
            const auto body = records.subspan(r.pos(), len);
            r.take(len);
            ByteReader b(body);
            bool good = false;
            uint32_t t = 0;
            switch (static_cast<RecordKind>(kind)) {
            case RecordKind::Sample: {
                Sample s;
                good = read_sample(b, s);
                t = s.t_100us;
                if (good)
                    d_.samples.push_back(std::move(s));
                break;
            }
            case RecordKind::Event: {
                Event e;
                good = read_event(b, e);
                t = e.t_100us;
                if (good)
                    d_.events.push_back(std::move(e));
                break;
            }
            case RecordKind::End:
                d_.end.t_100us = t = b.u32();
                d_.end.reason = b.str(kMaxText);
                good = !b.failed();
                d_.ended = good;
                break;
            default:
                return fail(ReadError::Malformed, rec_at, "unknown record kind " + std::to_string(kind));
            }
            if (!good || b.left() != 0)
                return fail(ReadError::Malformed, rec_at,
                            "a " + std::string(kind == 1 ? "sample" : kind == 2 ? "event" : "end") +
                                " record whose fields are out of range or do not fill its length");
            if (t < last_t_)
                return fail(ReadError::Malformed, rec_at, "time goes backwards");
            last_t_ = t;
        }
        return true;
    }

    std::span<const uint8_t> bytes_;
    Dive& d_;
    std::size_t header_end_ = 0;
    uint32_t last_t_ = 0;
};

} // namespace

Dive decode(std::span<const uint8_t> bytes) {
    Dive d;
    Decoder(bytes, d).run();
    return d;
}

} // namespace caracara::dive
