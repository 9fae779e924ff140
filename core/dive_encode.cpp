// The dive file's writing side (core/dive_format.hpp, docs/dive-format.md).
#include "core/byte_writer.hpp"
#include "core/crc32.hpp"
#include "core/dive_format.hpp"
#include "core/fixed_bytes.hpp"

#include <algorithm>

namespace caracara::dive {

namespace {

// The largest sample record: kind, length, time, requested and applied values, budget, flags,
// the thrusters, orientation, bus counters, then the distances.
constexpr std::size_t kMaxSampleRecord =
    1 + 2 + 4 + 2 * kThrusters * 2 + 2 + 1 + kThrusters * 18 + 3 * 4 + 2 * 4 + 1 + kMaxDistances * 2;

// u8 kind, u16 length, then the body `fill` writes.
template <typename Out, typename Fill>
void record(Out& out, RecordKind kind, Fill fill) {
    BasicByteWriter<Out> w(out);
    w.u8(static_cast<uint8_t>(kind));
    const std::size_t len_at = w.size();
    w.u16(0);
    const std::size_t body = w.size();
    fill(w);
    w.patch_u16(len_at, static_cast<uint16_t>(w.size() - body));
}

} // namespace

std::vector<uint8_t> encode_header(const Header& h) {
    std::vector<uint8_t> fields;
    ByteWriter f(fields);
    f.u64(h.start_unix_ms);
    f.u64(h.start_mono_ns);
    f.u32(h.loop_rate_hz);
    f.str(h.profile, kMaxText);
    f.str(h.reason, kMaxText);
    std::vector<uint8_t> out;
    ByteWriter w(out);
    w.raw(kMagic);
    w.u16(kVersion);
    w.u16(static_cast<uint16_t>(fields.size()));
    out.insert(out.end(), fields.begin(), fields.end());
    w.u32(crc32(fields));
    return out;
}

void encode_sample(std::vector<uint8_t>& records, const Sample& s) {
    // Written on the stack and appended at once: a sample is about a hundred fields, at every
    // control-loop tick.
    FixedBytes<kMaxSampleRecord> bytes;
    record(bytes, RecordKind::Sample, [&](auto& w) {
        w.u32(s.t_100us);
        for (int16_t v : s.requested)
            w.i16(v);
        for (int16_t v : s.applied)
            w.i16(v);
        w.i16(s.budget_limit);
        w.u8(s.flags);
        for (const ThrusterSample& t : s.thrusters) {
            w.i16(t.speed);
            w.u8(t.current_da);
            w.u8(t.temperature_c);
            w.u8(t.faults);
            w.u8(t.flags);
            w.u32(t.nacks);
            w.u32(t.bad_replies);
            w.u32(t.errors);
        }
        for (float v : s.orientation)
            w.f32(v);
        w.u32(s.bus_errors);
        w.u32(s.bus_recoveries);
        const std::size_t n = std::min(s.distances.size(), kMaxDistances);
        w.u8(static_cast<uint8_t>(n));
        for (std::size_t i = 0; i < n; ++i)
            w.u16(s.distances[i]);
    });
    if (!bytes.overflowed()) // cannot happen: kMaxSampleRecord is the record's bound
        records.insert(records.end(), bytes.begin(), bytes.end());
}

void encode_event(std::vector<uint8_t>& records, const Event& e) {
    record(records, RecordKind::Event, [&](ByteWriter& w) {
        w.u32(e.t_100us);
        w.u8(static_cast<uint8_t>(e.kind));
        w.u8(e.state);
        w.u8(e.kill_source);
        w.u8(e.thruster);
        w.u32(e.value);
        w.f32(e.number);
        w.str(e.text, kMaxText);
        w.str(e.client, kMaxText);
    });
}

void encode_end(std::vector<uint8_t>& records, const End& e) {
    record(records, RecordKind::End, [&](ByteWriter& w) {
        w.u32(e.t_100us);
        w.str(e.reason, kMaxText);
    });
}

std::vector<uint8_t> seal_block(std::span<const uint8_t> records) {
    std::vector<uint8_t> out;
    out.reserve(records.size() + 12);
    ByteWriter w(out);
    w.raw(kBlockMagic);
    w.u32(static_cast<uint32_t>(records.size()));
    w.u32(crc32(records));
    out.insert(out.end(), records.begin(), records.end());
    return out;
}

} // namespace caracara::dive
