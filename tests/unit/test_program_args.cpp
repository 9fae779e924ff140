// What every caracara program takes on its command line the same way (drivers/sdbus/program_args):
// "--name VALUE" and "--name=VALUE", the bus options answered by next(), flags taken only whole.
// The exits (help, version, usage errors) are the programs' own tests' (e2e, by running them).
#include "drivers/sdbus/program_args.hpp"
#include "tests/catch.hpp"

#include <string>
#include <vector>

using caracara::dbus::BusChoice;
using caracara::dbus::ProgramArgs;

namespace {

struct Argv {
    explicit Argv(std::vector<std::string> a) : args(std::move(a)) {
        for (auto& s : args)
            ptrs.push_back(s.data());
    }
    int argc() { return static_cast<int>(ptrs.size()); }
    char** argv() { return ptrs.data(); }
    std::vector<std::string> args;
    std::vector<char*> ptrs;
};

} // namespace

TEST_CASE("options with values in both forms; the bus options taken by next()") {
    Argv a({"prog", "--config", "/etc/x.toml", "--bus-address=unix:path=/tmp/bus", "--hardware=sim:/run/s",
            "--check"});
    ProgramArgs args("prog", "1", a.argc(), a.argv(), [] {});
    BusChoice bus;
    std::vector<std::string> seen;
    while (args.next(bus)) {
        if (args.is("--config"))
            seen.push_back("config " + args.value());
        else if (args.is("--hardware"))
            seen.push_back("hardware " + args.value());
        else if (args.flag("--check"))
            seen.push_back("check");
        else
            FAIL("unexpected argument");
    }
    CHECK(seen == std::vector<std::string>{"config /etc/x.toml", "hardware sim:/run/s", "check"});
    CHECK(bus.kind == BusChoice::Kind::Address);
    CHECK(bus.address == "unix:path=/tmp/bus");  // split at the first '=' only
}

TEST_CASE("the last bus option wins; a name is matched whole, not as a prefix") {
    Argv a({"prog", "--bus-address", "unix:path=/a", "--user", "--configfile", "--check=1"});
    ProgramArgs args("prog", "1", a.argc(), a.argv(), [] {});
    BusChoice bus;
    REQUIRE(args.next(bus));
    CHECK(bus.kind == BusChoice::Kind::User);
    CHECK_FALSE(args.is("--config"));
    REQUIRE(args.next(bus));
    CHECK(args.is("--check"));
    CHECK_FALSE(args.flag("--check"));  // a flag takes no value
    CHECK_FALSE(args.next(bus));
}
