// The dive file reader (core/dive_format.hpp) fed arbitrary bytes: what caracaractl plot and
// caracara-sim --replay read from disk. Invariants: it never crashes or reads out of bounds; a
// refused file names its problem at an offset inside the file and keeps only records read
// before it, each in range; what it read encodes again and decodes to the very same dive; a
// file cut anywhere is refused as truncated or malformed, never read as something longer.
#include "core/dive_format.hpp"
#include "fuzz/check.hpp"

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

using namespace caracara;

namespace {

void check_ranges(const dive::Dive& d) {
    for (const dive::Sample& s : d.samples) {
        FUZZ_CHECK(s.distances.size() <= dive::kMaxDistances, "%zu distances", s.distances.size());
        FUZZ_CHECK(s.bus_state() <= 2, "bus state %u", s.bus_state());
        for (const auto& t : s.thrusters)
            FUZZ_CHECK((t.faults & ~0x1F) == 0, "fault bits 0x%02x", t.faults);
    }
    for (const dive::Event& e : d.events) {
        FUZZ_CHECK(e.thruster < dive::kThrusters, "thruster %u", e.thruster);
        FUZZ_CHECK(e.text.size() <= dive::kMaxText && e.client.size() <= dive::kMaxText, "text too long");
    }
}

// The dive as the recorder would write it: the header, one block of every record in time order.
std::vector<uint8_t> reencode(const dive::Dive& d) {
    std::vector<uint8_t> out = dive::encode_header(d.header);
    std::vector<uint8_t> records;
    std::size_t e = 0;
    for (const dive::Sample& s : d.samples) {
        for (; e < d.events.size() && d.events[e].t_100us <= s.t_100us; ++e)
            dive::encode_event(records, d.events[e]);
        dive::encode_sample(records, s);
    }
    for (; e < d.events.size(); ++e)
        dive::encode_event(records, d.events[e]);
    if (d.ended)
        dive::encode_end(records, d.end);
    const std::vector<uint8_t> block = dive::seal_block(records);
    out.insert(out.end(), block.begin(), block.end());
    return out;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
    const std::span<const uint8_t> bytes(data, size);
    const dive::Dive d = dive::decode(bytes);
    check_ranges(d);
    if (!d.ok()) {
        FUZZ_CHECK(d.error_offset <= size, "error at %zu of %zu", d.error_offset, size);
        FUZZ_CHECK(!d.message.empty(), "no message for %s", std::string(dive::read_error_name(d.error)).c_str());
        return 0;
    }
    // Events and samples interleave by time in the re-encoding; the reader keeps them apart, so
    // the round trip compares each list.
    const dive::Dive again = dive::decode(reencode(d));
    FUZZ_CHECK(again.ok(), "re-encoded dive refused: %s", again.message.c_str());
    FUZZ_CHECK(again.samples == d.samples && again.events == d.events && again.ended == d.ended &&
                   again.end == d.end && again.header.profile == d.header.profile &&
                   again.header.start_unix_ms == d.header.start_unix_ms,
               "round trip changed the dive (%zu samples, %zu events)", d.samples.size(), d.events.size());
    // Cut before its last byte, a good file is never good (every block is checked whole).
    if (size > 0 && !d.samples.empty()) {
        const dive::Dive cut = dive::decode(bytes.first(size - 1));
        FUZZ_CHECK(!cut.ok() || cut.samples.size() <= d.samples.size(), "a cut file read longer");
    }
    return 0;
}
