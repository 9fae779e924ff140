// caracara-bridge's static files (tools/bridge/static_files.hpp): GET and HEAD of plain names
// under one directory, the content types, and every way out of it refused with 404.
#include "tests/catch.hpp"
#include "tools/bridge/static_files.hpp"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

using caracara::bridge::StaticFiles;
namespace http = boost::beast::http;

namespace {

struct Tree {
    std::filesystem::path root;
    Tree() {
        char tmpl[] = "/tmp/caracara-static.XXXXXX";
        root = ::mkdtemp(tmpl);
        std::filesystem::create_directories(root / "site" / "js");
        std::ofstream(root / "site" / "index.html") << "<p>index</p>";
        std::ofstream(root / "site" / "js" / "app.js") << "export {};";
        std::ofstream(root / "site" / ".secret") << "no";
        std::filesystem::create_directories(root / "site" / "dir.css");
        std::ofstream(root / "outside.txt") << "outside";
    }
    ~Tree() { std::filesystem::remove_all(root); }
    StaticFiles files() const { return StaticFiles((root / "site").string()); }
};

StaticFiles::Response ask(const StaticFiles& f, const std::string& target, http::verb verb = http::verb::get) {
    StaticFiles::Request req(verb, target, 11);
    return f.respond(req);
}

} // namespace

TEST_CASE("GET serves a file with its content type; / is index.html", "[bridge]") {
    const Tree t;
    const auto r = ask(t.files(), "/");
    CHECK(r.result() == http::status::ok);
    CHECK(r.body() == "<p>index</p>");
    CHECK(r[http::field::content_type] == "text/html; charset=utf-8");
    const auto js = ask(t.files(), "/js/app.js?v=1");
    CHECK(js.result() == http::status::ok);
    CHECK(js[http::field::content_type] == "text/javascript; charset=utf-8");
}

TEST_CASE("HEAD gives the length and no body; other methods 405", "[bridge]") {
    const Tree t;
    const auto h = ask(t.files(), "/index.html", http::verb::head);
    CHECK(h.result() == http::status::ok);
    CHECK(h.body().empty());
    CHECK(h[http::field::content_length] == "12");
    const auto p = ask(t.files(), "/index.html", http::verb::post);
    CHECK(p.result() == http::status::method_not_allowed);
    CHECK(p[http::field::allow] == "GET, HEAD");
}

TEST_CASE("no way out of the directory, no hidden file, no directory: 404", "[bridge]") {
    const Tree t;
    for (const char* target : {"/../outside.txt", "/js/../../outside.txt", "/%2e%2e/outside.txt", "//etc/passwd",
                               "/.secret", "/js/", "/dir.css", "/missing.html", "index.html", "/a b", "/x\\y"})
        CHECK(ask(t.files(), target).result() == http::status::not_found);
    CHECK(ask(StaticFiles(""), "/").result() == http::status::not_found);
}
