// The dive files in the recorder's directory: listed oldest first (their names sort by time),
// read whole, and deleted for rotation. Used by the recorder's writer thread, caracaractl and
// caracara-sim --replay.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace caracara {

inline constexpr const char* kDivePrefix = "dive-";
inline constexpr const char* kDiveSuffix = ".cdive";

struct DiveFile {
    std::string name;  // dive-20250101T120000.123Z.cdive
    std::string path;
    uint64_t size = 0;
};

// Oldest first; an unreadable or missing directory gives an empty list and `error` set.
std::vector<DiveFile> list_dive_files(const std::string& directory, std::string* error = nullptr);
// The file's bytes, or "" in `error` with the reason (errno's text).
bool read_whole_file(const std::string& path, std::vector<uint8_t>& out, std::string& error);
// "dive-20250101T120000.123Z.cdive" for a wall-clock time in milliseconds.
std::string dive_file_name(uint64_t unix_ms);

} // namespace caracara
