// The cockpit's files (docs/cockpit.md) served by caracara-bridge over plain HTTP on the same
// listener as the WebSocket: GET and HEAD of regular files under one directory, nothing else.
// A target is looked up only when every segment is a plain name (letters, digits, '-', '_',
// '.', no segment starting with '.'), so no path leaves the directory; anything else is 404.
#pragma once

#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>
#include <string>

namespace caracara::bridge {

class StaticFiles {
public:
    using Request = boost::beast::http::request<boost::beast::http::string_body>;
    using Response = boost::beast::http::response<boost::beast::http::string_body>;

    explicit StaticFiles(std::string root) : root_(std::move(root)) {}
    // The answer to a plain (not upgrading) HTTP request: 200 with the file, 404, or 405.
    Response respond(const Request& request) const;
    // The Content-Type of a file name, by its extension.
    static const char* content_type(const std::string& name);

private:
    std::string root_;
};

} // namespace caracara::bridge
