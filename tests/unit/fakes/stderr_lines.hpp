// What a piece of code writes on stderr (fd 2, as journald reads caracarad's), caught in a
// temporary file while it runs: its lines, without their newlines.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace caracara::test {

// Fails the test (REQUIRE) on a last line without its newline.
std::vector<std::string> stderr_lines(const std::function<void()>& write);

} // namespace caracara::test
