#include "tools/foxglove/dive_summary.hpp"

namespace caracara::foxglove {

std::string dive_end(const dive::Dive& d) {
    return !d.ok() ? std::string(dive::read_error_name(d.error)) : d.ended ? d.end.reason : "open";
}

DiveSummary summarize_dive(const DiveFile& file) {
    DiveSummary s;
    s.file = file;
    std::vector<uint8_t> bytes;
    if (!read_whole_file(file.path, bytes, s.read_error))
        return s;
    const dive::Dive d = dive::decode(bytes);
    const uint32_t last = d.ended ? d.end.t_100us : d.samples.empty() ? 0 : d.samples.back().t_100us;
    s.is_dive = d.error != dive::ReadError::NotADive;
    s.start_unix_ms = d.header.start_unix_ms;
    s.seconds = last / 10000.0;
    s.samples = d.samples.size();
    s.end = dive_end(d);
    return s;
}

std::vector<DiveSummary> summarize_dives(const std::string& directory, std::string* error) {
    std::vector<DiveSummary> out;
    for (const DiveFile& f : list_dive_files(directory, error))
        out.push_back(summarize_dive(f));
    return out;
}

} // namespace caracara::foxglove
