#include "tools/caracaractl/commissioning_commands.hpp"

#include "tools/caracaractl/render.hpp"

#include <cstdio>
#include <iostream>

namespace caracara::ctl {

namespace {

// Detection pulses eight thrusters, each after the vehicle settles (up to its settle timeout).
constexpr uint64_t kDetectTimeoutUsec = 600'000'000;

} // namespace

int cmd_motor_test(Client& c, const Args& a, const Options& o) {
    const int32_t thruster = parse_int(a[0], "thruster");
    if (!o.value)
        usage_error("motor-test needs --value V");
    return hold_command(c, "MotorTest", append_args("ii", thruster, *o.value),
                        strf("MotorTest(%d, %d)", thruster, *o.value), o.hold);
}

int cmd_detect_directions(Client& c, const Args&, const Options& o) {
    caracara::dbus::MessagePtr reply = c.call(kRootPath, kVehicleIface, "DetectDirections", {}, kDetectTimeoutUsec);
    const Value rows = read_value(reply.get());
    const Value fragment = read_value(reply.get());
    std::cout << strf("%-8s %-13s %10s %10s %10s %10s %7s\n", "thruster", "verdict", "yaw", "pitch", "roll", "along",
                      "margin");
    bool all_decided = true;
    for (size_t i = 0; i < rows.items.size(); ++i) {
        const auto& f = rows.items[i].items;
        if (f.size() != 6)
            throw Failure{kExitUnavailable, "DetectDirections answered a malformed row"};
        all_decided = all_decided && f[0].s != "inconclusive";
        std::cout << strf("%-8zu %-13s %+10.4f %+10.4f %+10.4f %+10.4f %7.1f\n", i, f[0].s.c_str(), f[1].number(),
                          f[2].number(), f[3].number(), f[4].number(), f[5].number());
    }
    std::cout << "(rad: the attitude change over each pulse; margin: the change along the mixing's rotation\n"
                 " over commissioning.detect_threshold_mrad)\n";
    if (!o.write_path.empty()) {
        FILE* f = std::fopen(o.write_path.c_str(), "w");
        if (!f || std::fputs(fragment.s.c_str(), f) < 0 || std::fclose(f) != 0)
            throw Failure{kExitUnavailable, "cannot write " + o.write_path};
        std::cout << "wrote the [[thruster]] fragment to " << o.write_path << "\n";
    }
    return all_decided ? kExitOk : kExitRefused;
}

} // namespace caracara::ctl
