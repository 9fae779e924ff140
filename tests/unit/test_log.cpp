// daemon/loop/log: the lines caracarad writes on stderr as journald reads them (sd-daemon(3)):
// each message one line, its priority in the "<N>" prefix (error 3, warning 4, notice 5,
// info 6), a message too long for the buffer cut, never split; a thruster fault's change one
// line of its own at warning (raised) or notice (cleared) when stderr is not the journal.
#include "daemon/loop/log.hpp"

#include "tests/catch.hpp"
#include "tests/unit/fakes/stderr_lines.hpp"

#include <cstdlib>
#include <string>
#include <vector>

using namespace caracara;
using namespace caracara::test;

TEST_CASE("log: each level one line, its journald priority in front") {
    const auto lines = stderr_lines([] {
        log_error("bus %s lost", "i2c-1");
        log_warning("thruster %d slow", 3);
        log_notice("armed by %s", ":1.7");
        log_info("%zu KiB unlocked", std::size_t{42});
    });
    CHECK(lines == std::vector<std::string>{"<3>bus i2c-1 lost", "<4>thruster 3 slow", "<5>armed by :1.7",
                                            "<6>42 KiB unlocked"});
}

TEST_CASE("log: a message too long for one line is cut, still one line with its priority") {
    const std::string reason(3000, 'x');
    const auto lines = stderr_lines([&] { log_warning("kill: %s", reason.c_str()); });
    REQUIRE(lines.size() == 1);
    CHECK(lines[0].rfind("<4>kill: xxx", 0) == 0);
    CHECK(lines[0].size() < reason.size());
    CHECK(lines[0].find('\n') == std::string::npos);
}

TEST_CASE("log: a thruster fault's change, off the journal, a plain line at warning or notice") {
    // JOURNAL_STREAM naming another stream than stderr: the plain line, as under a terminal.
    ::setenv("JOURNAL_STREAM", "0:0", 1);
    const auto lines = stderr_lines([] {
        log_thruster_fault(3, "overtemp", true);
        log_thruster_fault(3, "overtemp", false);
    });
    CHECK(lines == std::vector<std::string>{"<4>thruster 3 raised fault overtemp", "<5>thruster 3 cleared fault overtemp"});
}
