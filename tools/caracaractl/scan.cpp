#include "tools/caracaractl/scan.hpp"

#include "tools/caracaractl/render.hpp"

#include <iostream>
#include <string>

namespace caracara::ctl {

using namespace caracara::client;

namespace {

// Probes one at a time between the routine transfers: seconds at most on a healthy bus.
constexpr uint64_t kScanTimeoutUsec = 120'000'000;

std::string segment(int64_t mux, int64_t channel) {
    return channel < 0 ? std::string("trunk") : strf("0x%02llx/%lld", (long long)mux, (long long)channel);
}

} // namespace

int scan_bus(Client& c) {
    caracara::dbus::MessagePtr reply = c.call(kRootPath, kVehicleIface, "ScanBus", {}, kScanTimeoutUsec);
    const Value devices = read_value(reply.get());
    const Value thrusters = read_value(reply.get());
    bool matches = true;
    std::cout << "answered:\n" << strf("%-10s %-8s %-9s %-9s %s\n", "mux/ch", "address", "variant", "revision", "thruster");
    for (const Value& row : devices.items) {
        const auto& f = row.items;
        if (f.size() != 6)
            throw Failure{kExitUnavailable, "ScanBus answered a malformed device row"};
        const int64_t thruster = f[5].integer();
        matches = matches && thruster >= 0;
        std::cout << strf("%-10s 0x%02llx     %-9s %-9lld %s\n", segment(f[0].integer(), f[1].integer()).c_str(),
                          (unsigned long long)f[2].integer(), f[3].s.empty() ? "?" : f[3].s.c_str(),
                          (long long)f[4].integer(),
                          thruster < 0 ? "unexpected" : std::to_string(thruster).c_str());
    }
    if (devices.items.empty())
        std::cout << "(nothing answered)\n";
    std::cout << "\n" << strf("%-8s %-14s %s\n", "thruster", "verdict", "what to do");
    for (size_t i = 0; i < thrusters.items.size(); ++i) {
        const auto& f = thrusters.items[i].items;
        if (f.size() != 2)
            throw Failure{kExitUnavailable, "ScanBus answered a malformed verdict"};
        matches = matches && f[0].s == "ok";
        std::cout << strf("%-8zu %-14s %s\n", i, f[0].s.c_str(), f[1].s.c_str());
    }
    for (const Value& row : devices.items)
        if (row.items[5].integer() < 0)
            std::cout << strf("unexpected device on %s at 0x%02llx: remove it, or give it a [[thruster]] table\n",
                              segment(row.items[0].integer(), row.items[1].integer()).c_str(),
                              (unsigned long long)row.items[2].integer());
    std::cout << (matches ? "the bus matches the configuration\n" : "the bus does NOT match the configuration\n");
    return matches ? kExitOk : kExitRefused;
}

} // namespace caracara::ctl
