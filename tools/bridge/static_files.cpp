#include "tools/bridge/static_files.hpp"

#include <fstream>
#include <sstream>
#include <string_view>
#include <sys/stat.h>

namespace caracara::bridge {

namespace http = boost::beast::http;

namespace {

// "/", "/index.html", "/js/app.js" -> the relative path, or "" when the target is not a plain name.
std::string relative_path(std::string_view target) {
    const auto query = target.find('?');
    std::string_view path = target.substr(0, query);
    if (!path.starts_with('/'))
        return "";
    path.remove_prefix(1);
    if (path.empty())
        return "index.html";
    std::size_t at = 0;
    while (at <= path.size()) {
        const auto slash = path.find('/', at);
        const std::string_view segment = path.substr(at, slash == std::string_view::npos ? std::string_view::npos : slash - at);
        if (segment.empty() || segment.front() == '.')
            return "";
        for (const char c : segment)
            if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' ||
                  c == '.'))
                return "";
        if (slash == std::string_view::npos)
            break;
        at = slash + 1;
    }
    return std::string(path);
}

StaticFiles::Response plain(http::status status, unsigned version, const char* text) {
    StaticFiles::Response res(status, version);
    res.set(http::field::content_type, "text/plain; charset=utf-8");
    res.body() = text;
    return res;
}

} // namespace

const char* StaticFiles::content_type(const std::string& name) {
    static constexpr struct { std::string_view ext; const char* type; } kTypes[] = {
        {".html", "text/html; charset=utf-8"}, {".js", "text/javascript; charset=utf-8"},
        {".css", "text/css; charset=utf-8"},   {".json", "application/json"},
        {".svg", "image/svg+xml"},             {".png", "image/png"},
        {".ico", "image/x-icon"},              {".txt", "text/plain; charset=utf-8"},
    };
    for (const auto& t : kTypes)
        if (std::string_view(name).ends_with(t.ext))
            return t.type;
    return "application/octet-stream";
}

StaticFiles::Response StaticFiles::respond(const Request& request) const {
    const unsigned version = request.version();
    Response res;
    if (request.method() != http::verb::get && request.method() != http::verb::head) {
        res = plain(http::status::method_not_allowed, version, "caracara-bridge serves GET and HEAD only\n");
        res.set(http::field::allow, "GET, HEAD");
    } else if (const std::string rel = relative_path({request.target().data(), request.target().size()});
               rel.empty() || root_.empty()) {
        res = plain(http::status::not_found, version, "not found\n");
    } else {
        const std::string path = root_ + "/" + rel;
        struct stat st {};
        std::ifstream in;
        if (::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode))
            in.open(path, std::ios::binary);
        if (!in.is_open() || !in) {
            res = plain(http::status::not_found, version, "not found\n");
        } else {
            std::ostringstream body;
            body << in.rdbuf();
            res = Response(http::status::ok, version);
            res.set(http::field::content_type, content_type(rel));
            res.body() = std::move(body).str();
        }
    }
    // The page loads nothing but its own files and talks to nothing but its own bridge.
    res.set(http::field::server, "caracara-bridge");
    res.set(http::field::cache_control, "no-cache");
    res.set("X-Content-Type-Options", "nosniff");
    res.set("Content-Security-Policy", "default-src 'self'; connect-src 'self'; img-src 'self' data: blob:; "
                                        "frame-ancestors 'none'");
    res.keep_alive(false);
    res.prepare_payload();
    if (request.method() == http::verb::head)
        res.body().clear(); // Content-Length stays the file's
    return res;
}

} // namespace caracara::bridge
