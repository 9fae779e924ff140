// An MCAP file writer (MCAP format specification, version 0: "mcap.dev/spec"), written from the
// specification because Debian packages no MCAP library. Pure: records are built in memory and
// finish() returns the whole file. Chunked without compression, so the file carries the index a
// reader seeks with: each chunk is followed by one Message Index per channel, and the summary
// holds Schema, Channel, Statistics and Chunk Index records, then a Summary Offset per group.
// Every CRC is filled in (data section, each chunk's records, summary), with the project's
// CRC-32 (core/crc32.hpp, the IEEE polynomial MCAP specifies).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace caracara::foxglove {

class McapWriter {
public:
    // profile: "" (none); library: who wrote the file (the Header record).
    McapWriter(std::string profile, std::string library, std::size_t chunk_bytes = 1u << 20);

    // Ids start at 1 (schema id 0 means "no schema").
    uint16_t add_schema(std::string_view name, std::string_view encoding, std::string_view data);
    using Map = std::map<std::string, std::string>;
    // metadata: the channel's (rosbag2 keeps a topic's offered_qos_profiles there).
    uint16_t add_channel(uint16_t schema_id, std::string_view topic, std::string_view message_encoding,
                         const Map& metadata = {});
    // A Metadata record (rosbag2's "rosbag2" with ROS_DISTRO), indexed in the summary.
    void add_metadata(std::string_view name, const Map& metadata);
    // Messages in any order of time; each channel's sequence counts from 0.
    void add_message(uint16_t channel_id, uint64_t log_time, uint64_t publish_time, std::string_view data);

    // Closes the last chunk, writes Data End, the summary and the footer; the writer is spent.
    std::vector<uint8_t> finish();

    uint64_t message_count() const { return message_count_; }

private:
    struct Schema { uint16_t id; std::string name, encoding, data; };
    struct Channel { uint16_t id, schema_id; std::string topic, encoding; Map metadata; uint32_t sequence = 0; };
    struct MetadataIndex { uint64_t offset, length; std::string name; };
    struct ChunkIndex {
        uint64_t start_time, end_time, offset, length, index_length, records_size;
        std::map<uint16_t, uint64_t> index_offsets;
    };

    void flush_chunk();
    void write_schema(std::vector<uint8_t>& out, const Schema& s) const;
    void write_channel(std::vector<uint8_t>& out, const Channel& c) const;

    std::size_t chunk_bytes_;
    std::vector<uint8_t> file_;     // magic, header, and the data section so far
    std::vector<Schema> schemas_;
    std::vector<Channel> channels_;
    std::vector<MetadataIndex> metadata_indexes_;
    // The open chunk: its records, message index entries per channel (time, offset), times.
    std::vector<uint8_t> chunk_;
    std::map<uint16_t, std::vector<std::pair<uint64_t, uint64_t>>> chunk_index_;
    uint64_t chunk_start_ = 0, chunk_end_ = 0;
    std::vector<ChunkIndex> chunk_indexes_;
    uint64_t message_count_ = 0, start_time_ = 0, end_time_ = 0;
    std::map<uint16_t, uint64_t> channel_counts_;
};

} // namespace caracara::foxglove
