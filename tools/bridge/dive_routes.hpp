// The recorded dives over HTTP for the cockpit (docs/cockpit.md), read from the recorder's
// directory (the bridge only reads it; caracarad writes it):
//   /dives/             the list, as `caracaractl dives` has it (JSON)
//   /dives/NAME.cdive   the file itself
//   /dives/NAME.mcap    the dive as MCAP, converted on the fly (tools/foxglove/dive_mcap)
//   /dives/NAME.json    the applied thrust over time, for the page's plot
// NAME is only ever one of the listed dives' names, so nothing else in the directory is reachable.
// A dive over 32 MiB (4 MiB for .mcap) is answered 413, naming caracaractl export: one answer's
// memory is bounded. Runs on the DiveWorker's thread (it reads the disk, for seconds at times).
#pragma once

#include "tools/bridge/static_files.hpp"

#include <string>
#include <string_view>

namespace caracara::bridge {

class DiveRoutes {
public:
    static constexpr std::string_view kPrefix = "/dives/";

    explicit DiveRoutes(std::string directory) : dir_(std::move(directory)) {}
    // A GET or HEAD of a target under kPrefix: 200, 404, 405 or 413.
    StaticFiles::Response respond(const StaticFiles::Request& request) const;

private:
    std::string dir_;
};

} // namespace caracara::bridge
