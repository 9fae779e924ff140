#include "tools/bridge/dive_routes.hpp"

#include "tools/foxglove/dive_mcap.hpp"
#include "tools/foxglove/dive_summary.hpp"

#include <nlohmann/json.hpp>
#include <optional>

namespace caracara::bridge {

namespace http = boost::beast::http;
namespace fg = caracara::foxglove;
using nlohmann::json;

namespace {

constexpr std::size_t kPlotPoints = 2000; // the plot's samples at most (every Nth)
// What one answer may hold, so the bridge's memory stays within its unit's MemoryMax= (a dive
// can be as large as the whole directory's bound). A dive's MCAP is about 11 times the dive
// (JSON messages): converting is for dives up to about 6 minutes; longer ones are converted
// where they are read, with caracaractl export.
constexpr uint64_t kMaxServedBytes = 32u << 20;
constexpr uint64_t kMaxConvertedBytes = 4u << 20;

std::string list_json(const std::vector<fg::DiveSummary>& dives) {
    json out = json::array();
    for (const auto& d : dives)
        out.push_back({{"name", d.file.name.substr(0, d.file.name.size() - std::string_view(kDiveSuffix).size())},
                       {"file", d.file.name},
                       {"size", d.file.size},
                       {"readable", d.read_error.empty()},
                       {"start_ms", d.start_unix_ms},
                       {"seconds", d.seconds},
                       {"samples", d.samples},
                       {"end", d.read_error.empty() ? d.end : d.read_error}});
    return out.dump();
}

std::string plot_json(const dive::Dive& d) {
    const std::size_t step = d.samples.size() / kPlotPoints + 1;
    json t = json::array(), applied = json::array();
    for (std::size_t m = 0; m < dive::kThrusters; ++m)
        applied.push_back(json::array());
    for (std::size_t i = 0; i < d.samples.size(); i += step) {
        t.push_back(d.samples[i].t_100us / 10000.0);
        for (std::size_t m = 0; m < dive::kThrusters; ++m)
            applied[m].push_back(d.samples[i].applied[m]);
    }
    return json{{"t", t}, {"applied", applied}, {"end", fg::dive_end(d)}}.dump();
}

} // namespace

StaticFiles::Response DiveRoutes::respond(const StaticFiles::Request& request) const {
    StaticFiles::Response res(http::status::ok, request.version());
    const std::string_view target(request.target().data(), request.target().size());
    const std::string_view rest = target.substr(kPrefix.size(), target.find('?') == std::string_view::npos
                                                                   ? std::string_view::npos
                                                                   : target.find('?') - kPrefix.size());
    std::string error;
    auto not_found = [&](const std::string& why) {
        res.result(http::status::not_found);
        res.set(http::field::content_type, "text/plain; charset=utf-8");
        res.body() = why + "\n";
    };
    if (request.method() != http::verb::get && request.method() != http::verb::head) {
        res.result(http::status::method_not_allowed);
        res.set(http::field::allow, "GET, HEAD");
    } else if (rest.empty()) {
        const auto dives = fg::summarize_dives(dir_, &error); // reads every dive: only for the list
        if (!error.empty())
            not_found("cannot list dives: " + error);
        else {
            res.set(http::field::content_type, "application/json");
            res.body() = list_json(dives);
        }
    } else {
        const auto dot = rest.rfind('.');
        const std::string_view name = rest.substr(0, dot), ext = dot == std::string_view::npos ? "" : rest.substr(dot);
        std::optional<DiveFile> found;
        for (const DiveFile& f : list_dive_files(dir_, &error))
            if (f.name == std::string(name) + kDiveSuffix)
                found = f;
        std::vector<uint8_t> bytes;
        if (!found || (ext != ".cdive" && ext != ".mcap" && ext != ".json")) {
            not_found("no such dive");
        } else if (found->size > (ext == ".mcap" ? kMaxConvertedBytes : kMaxServedBytes)) {
            res.result(http::status::payload_too_large);
            res.set(http::field::content_type, "text/plain; charset=utf-8");
            res.body() = "this dive is too large to " + std::string(ext == ".mcap" ? "convert" : "send") +
                         " here (" + std::to_string(found->size >> 20) + " MiB): copy " + found->name +
                         " and run caracaractl export on it\n";
        } else if (!read_whole_file(found->path, bytes, error)) {
            not_found("cannot read the dive: " + error);
        } else if (ext == ".cdive") {
            res.set(http::field::content_type, "application/octet-stream");
            res.set(http::field::content_disposition, "attachment; filename=\"" + found->name + "\"");
            res.body().assign(bytes.begin(), bytes.end());
        } else {
            const dive::Dive d = dive::decode(bytes);
            if (ext == ".json") {
                res.set(http::field::content_type, "application/json");
                res.body() = plot_json(d);
            } else {
                const std::vector<uint8_t> mcap = fg::dive_to_mcap(d);
                res.set(http::field::content_type, "application/octet-stream");
                res.set(http::field::content_disposition, "attachment; filename=\"" + std::string(name) + ".mcap\"");
                res.body().assign(mcap.begin(), mcap.end());
            }
        }
    }
    res.set(http::field::server, "caracara-bridge");
    res.set(http::field::cache_control, "no-cache");
    res.set("X-Content-Type-Options", "nosniff");
    res.keep_alive(false);
    res.prepare_payload();
    if (request.method() == http::verb::head)
        res.body().clear();
    return res;
}

} // namespace caracara::bridge
