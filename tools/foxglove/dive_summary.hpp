// A line of `caracaractl dives` per dive file: when it started, how long it lasted, its
// samples and how it ended; shared by caracaractl and the cockpit's dive list (caracara-bridge).
#pragma once

#include "core/dive_format.hpp"
#include "drivers/platform/dive_files.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace caracara::foxglove {

struct DiveSummary {
    DiveFile file;
    std::string read_error;       // not empty: the file could not be read (nothing else is set)
    bool is_dive = false;         // false: not a dive file at all
    uint64_t start_unix_ms = 0;
    double seconds = 0;           // to its end, or to its last sample when it has none
    std::size_t samples = 0;
    std::string end;              // the end's reason, "open", or the decoder's error name
};

// How a dive ended: its end's reason, "open", or the decoder's error name.
std::string dive_end(const dive::Dive& d);
DiveSummary summarize_dive(const DiveFile& file);
// Every dive in a directory, oldest first; `error` set when the directory cannot be listed.
std::vector<DiveSummary> summarize_dives(const std::string& directory, std::string* error);

} // namespace caracara::foxglove
