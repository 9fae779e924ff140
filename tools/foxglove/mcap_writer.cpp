#include "tools/foxglove/mcap_writer.hpp"

#include "core/byte_writer.hpp"
#include "core/crc32.hpp"

#include <algorithm>
#include <stdexcept>

namespace caracara::foxglove {

namespace {

constexpr uint8_t kMagic[] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};

enum Op : uint8_t {
    kHeader = 0x01, kFooter = 0x02, kSchema = 0x03, kChannel = 0x04, kMessage = 0x05, kChunk = 0x06,
    kMessageIndex = 0x07, kChunkIndex = 0x08, kStatistics = 0x0B, kMetadata = 0x0C, kMetadataIndex = 0x0D,
    kSummaryOffset = 0x0E, kDataEnd = 0x0F,
};

// A record: opcode, u64 length of the content, content (appended by `body`).
template <typename F>
void record(std::vector<uint8_t>& out, uint8_t op, F body) {
    ByteWriter w(out);
    w.u8(op);
    const std::size_t at = out.size();
    w.u64(0);
    body(w);
    const uint64_t length = out.size() - at - 8;
    for (int i = 0; i < 8; ++i)
        out[at + static_cast<std::size_t>(i)] = static_cast<uint8_t>(length >> (8 * i));
}

void string(ByteWriter& w, std::string_view s) {
    w.u32(static_cast<uint32_t>(s.size()));
    w.raw(s);
}

// A Map<string, string>: its byte length, then each key and value as a string.
void map(ByteWriter& w, std::vector<uint8_t>& out, const std::map<std::string, std::string>& m) {
    const std::size_t at = out.size();
    w.u32(0);
    for (const auto& [k, v] : m) {
        string(w, k);
        string(w, v);
    }
    const auto length = static_cast<uint32_t>(out.size() - at - 4);
    for (int i = 0; i < 4; ++i)
        out[at + static_cast<std::size_t>(i)] = static_cast<uint8_t>(length >> (8 * i));
}

uint32_t crc(const std::vector<uint8_t>& v, std::size_t from, std::size_t to) {
    return caracara::crc32(std::span<const uint8_t>(v.data() + from, to - from));
}

} // namespace

McapWriter::McapWriter(std::string profile, std::string library, std::size_t chunk_bytes)
    : chunk_bytes_(chunk_bytes) {
    file_.assign(std::begin(kMagic), std::end(kMagic));
    record(file_, kHeader, [&](ByteWriter& w) {
        string(w, profile);
        string(w, library);
    });
}

uint16_t McapWriter::add_schema(std::string_view name, std::string_view encoding, std::string_view data) {
    const auto id = static_cast<uint16_t>(schemas_.size() + 1);
    schemas_.push_back({id, std::string(name), std::string(encoding), std::string(data)});
    write_schema(file_, schemas_.back());
    return id;
}

uint16_t McapWriter::add_channel(uint16_t schema_id, std::string_view topic, std::string_view message_encoding,
                                 const Map& metadata) {
    const auto id = static_cast<uint16_t>(channels_.size() + 1);
    channels_.push_back({id, schema_id, std::string(topic), std::string(message_encoding), metadata});
    write_channel(file_, channels_.back());
    return id;
}

void McapWriter::add_metadata(std::string_view name, const Map& metadata) {
    // In the data section, outside any chunk; its index in the summary.
    const uint64_t offset = file_.size();
    record(file_, kMetadata, [&](ByteWriter& w) {
        string(w, name);
        map(w, file_, metadata);
    });
    metadata_indexes_.push_back({offset, file_.size() - offset, std::string(name)});
}

void McapWriter::write_schema(std::vector<uint8_t>& out, const Schema& s) const {
    record(out, kSchema, [&](ByteWriter& w) {
        w.u16(s.id);
        string(w, s.name);
        string(w, s.encoding);
        string(w, s.data); // bytes: u32 length and the data, as a string
    });
}

void McapWriter::write_channel(std::vector<uint8_t>& out, const Channel& c) const {
    record(out, kChannel, [&](ByteWriter& w) {
        w.u16(c.id);
        w.u16(c.schema_id);
        string(w, c.topic);
        string(w, c.encoding);
        map(w, out, c.metadata);
    });
}

void McapWriter::add_message(uint16_t channel_id, uint64_t log_time, uint64_t publish_time, std::string_view data) {
    if (channel_id == 0 || channel_id > channels_.size())
        throw std::invalid_argument("MCAP message on an unknown channel");
    Channel& c = channels_[channel_id - 1];
    if (chunk_.empty()) {
        chunk_start_ = chunk_end_ = log_time;
    }
    chunk_index_[channel_id].emplace_back(log_time, chunk_.size());
    record(chunk_, kMessage, [&](ByteWriter& w) {
        w.u16(channel_id);
        w.u32(c.sequence++);
        w.u64(log_time);
        w.u64(publish_time);
        w.raw(data);
    });
    chunk_start_ = std::min(chunk_start_, log_time);
    chunk_end_ = std::max(chunk_end_, log_time);
    start_time_ = message_count_ == 0 ? log_time : std::min(start_time_, log_time);
    end_time_ = message_count_ == 0 ? log_time : std::max(end_time_, log_time);
    ++message_count_;
    ++channel_counts_[channel_id];
    if (chunk_.size() >= chunk_bytes_)
        flush_chunk();
}

void McapWriter::flush_chunk() {
    if (chunk_.empty())
        return;
    ChunkIndex index{chunk_start_, chunk_end_, file_.size(), 0, 0, chunk_.size(), {}};
    const uint32_t records_crc = caracara::crc32(chunk_);
    record(file_, kChunk, [&](ByteWriter& w) {
        w.u64(chunk_start_);
        w.u64(chunk_end_);
        w.u64(chunk_.size());
        w.u32(records_crc);
        string(w, ""); // no compression
        w.u64(chunk_.size());
        w.raw(std::string_view(reinterpret_cast<const char*>(chunk_.data()), chunk_.size()));
    });
    index.length = file_.size() - index.offset;
    const std::size_t indexes_start = file_.size();
    for (auto& item : chunk_index_) {
        const uint16_t channel = item.first;
        auto& entries = item.second;
        // The entries sorted by time, as the specification asks.
        std::stable_sort(entries.begin(), entries.end(),
                         [](const auto& a, const auto& b) { return a.first < b.first; });
        index.index_offsets[channel] = file_.size();
        record(file_, kMessageIndex, [&](ByteWriter& w) {
            w.u16(channel);
            w.u32(static_cast<uint32_t>(entries.size() * 16));
            for (const auto& [time, offset] : entries) {
                w.u64(time);
                w.u64(offset);
            }
        });
    }
    index.index_length = file_.size() - indexes_start;
    chunk_indexes_.push_back(std::move(index));
    chunk_.clear();
    chunk_index_.clear();
}

std::vector<uint8_t> McapWriter::finish() {
    flush_chunk();
    const uint32_t data_crc = crc(file_, 0, file_.size());
    record(file_, kDataEnd, [&](ByteWriter& w) { w.u32(data_crc); });

    const uint64_t summary_start = file_.size();
    struct Group { uint8_t op; uint64_t start, length; };
    std::vector<Group> groups;
    auto group = [&](uint8_t op, auto write) {
        const uint64_t start = file_.size();
        write();
        if (file_.size() > start)
            groups.push_back({op, start, file_.size() - start});
    };
    group(kSchema, [&] { for (const Schema& s : schemas_) write_schema(file_, s); });
    group(kChannel, [&] { for (const Channel& c : channels_) write_channel(file_, c); });
    group(kStatistics, [&] {
        record(file_, kStatistics, [&](ByteWriter& w) {
            w.u64(message_count_);
            w.u16(static_cast<uint16_t>(schemas_.size()));
            w.u32(static_cast<uint32_t>(channels_.size()));
            w.u32(0); // attachments
            w.u32(static_cast<uint32_t>(metadata_indexes_.size()));
            w.u32(static_cast<uint32_t>(chunk_indexes_.size()));
            w.u64(start_time_);
            w.u64(end_time_);
            w.u32(static_cast<uint32_t>(channel_counts_.size() * 10));
            for (const auto& [channel, count] : channel_counts_) {
                w.u16(channel);
                w.u64(count);
            }
        });
    });
    group(kChunkIndex, [&] {
        for (const ChunkIndex& c : chunk_indexes_)
            record(file_, kChunkIndex, [&](ByteWriter& w) {
                w.u64(c.start_time);
                w.u64(c.end_time);
                w.u64(c.offset);
                w.u64(c.length);
                w.u32(static_cast<uint32_t>(c.index_offsets.size() * 10));
                for (const auto& [channel, offset] : c.index_offsets) {
                    w.u16(channel);
                    w.u64(offset);
                }
                w.u64(c.index_length);
                string(w, "");
                w.u64(c.records_size); // compressed size: the same, uncompressed
                w.u64(c.records_size);
            });
    });
    group(kMetadataIndex, [&] {
        for (const MetadataIndex& m : metadata_indexes_)
            record(file_, kMetadataIndex, [&](ByteWriter& w) {
                w.u64(m.offset);
                w.u64(m.length);
                string(w, m.name);
            });
    });
    const uint64_t offsets_start = file_.size();
    for (const Group& g : groups)
        record(file_, kSummaryOffset, [&](ByteWriter& w) {
            w.u8(g.op);
            w.u64(g.start);
            w.u64(g.length);
        });
    // The footer's CRC covers the summary and the footer up to the CRC itself.
    record(file_, kFooter, [&](ByteWriter& w) {
        w.u64(summary_start);
        w.u64(offsets_start);
        w.u32(0);
    });
    const uint32_t summary_crc = crc(file_, summary_start, file_.size() - 4);
    for (int i = 0; i < 4; ++i)
        file_[file_.size() - 4 + static_cast<std::size_t>(i)] = static_cast<uint8_t>(summary_crc >> (8 * i));
    file_.insert(file_.end(), std::begin(kMagic), std::end(kMagic));
    return std::move(file_);
}

} // namespace caracara::foxglove
