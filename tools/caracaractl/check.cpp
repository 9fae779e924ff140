#include "tools/caracaractl/check.hpp"

#include "tools/caracaractl/render.hpp"

#include <iostream>

namespace caracara::ctl {

namespace {

// The preflight watches for about a second; the reply can wait behind a busy daemon.
constexpr uint64_t kPreflightTimeoutUsec = 30'000'000;

} // namespace

int run_check(Client& client) {
    caracara::dbus::MessagePtr reply = client.call(kRootPath, kVehicleIface, "Preflight", {}, kPreflightTimeoutUsec);
    const Value rows = read_value(reply.get());
    std::cout << strf("%-14s %-6s %s\n", "item", "go?", "observed");
    std::size_t no_go = 0;
    for (const Value& row : rows.items) {
        const auto& f = row.items;
        if (f.size() != 4)
            throw Failure{kExitUnavailable, "Preflight answered a malformed row"};
        const bool go = f[1].boolean();
        std::cout << strf("%-14s %-6s %s\n", f[0].s.c_str(), go ? "go" : "NO-GO", f[2].s.c_str());
        if (!go) {
            ++no_go;
            std::cout << strf("%-14s %-6s -> %s\n", "", "", f[3].s.c_str());
        }
    }
    if (no_go == 0) {
        std::cout << "preflight: all go\n";
        return kExitOk;
    }
    std::cout << strf("preflight: %zu no-go, not ready to dive\n", no_go);
    return kExitRefused;
}

} // namespace caracara::ctl
