#include "tests/unit/fakes/stderr_lines.hpp"

#include "tests/catch.hpp"

#include <cstdio>
#include <stdexcept>
#include <unistd.h>

namespace caracara::test {

std::vector<std::string> stderr_lines(const std::function<void()>& write) {
    std::FILE* tmp = std::tmpfile();
    if (!tmp)
        throw std::runtime_error("tmpfile");
    std::fflush(stderr);
    const int saved = ::dup(2);
    ::dup2(::fileno(tmp), 2);
    write();
    std::fflush(stderr);
    ::dup2(saved, 2);
    ::close(saved);
    std::string all;
    std::rewind(tmp);
    for (int c; (c = std::fgetc(tmp)) != EOF;)
        all += static_cast<char>(c);
    std::fclose(tmp);
    std::vector<std::string> lines;
    for (std::size_t at = 0; at < all.size();) {
        const std::size_t nl = all.find('\n', at);
        REQUIRE(nl != std::string::npos); // every line ends
        lines.push_back(all.substr(at, nl - at));
        at = nl + 1;
    }
    return lines;
}

} // namespace caracara::test
