#include "tools/caracaractl/vehicle_commands.hpp"

#include "tools/caracaractl/monitor.hpp"
#include "tools/caracaractl/render.hpp"

#include <iostream>
#include <unistd.h>

namespace caracara::ctl {

int cmd_status(Client& c, const Args&, const Options&) {
    print_status(std::cout, c.get_objects());
    return kExitOk;
}

int cmd_monitor(Client& c, const Args&, const Options& o) { return run_monitor(c, o.all); }

int cmd_kill(Client& c, const Args&, const Options&) {
    c.call(kRootPath, kVehicleIface, "Kill");
    return kExitOk;
}

int cmd_clear_kill(Client& c, const Args&, const Options&) {
    c.call(kRootPath, kVehicleIface, "ClearKill");
    return kExitOk;
}

int cmd_clear_kill_override(Client& c, const Args& a, const Options&) {
    c.call(kRootPath, kVehicleIface, "ClearKillOverride", append_args("s", a[0].c_str()));
    return kExitOk;
}

int cmd_profile(Client& c, const Args& a, const Options&) {
    c.call(kRootPath, kVehicleIface, "SetProfile", append_args("s", a[0].c_str()));
    return kExitOk;
}

int cmd_leds(Client& c, const Args& a, const Options&) {
    const uint8_t r = parse_byte(a[0], "R"), g = parse_byte(a[1], "G"), b = parse_byte(a[2], "B");
    c.call(kRootPath, kVehicleIface, "SetLeds", append_args("yyy", r, g, b));
    return kExitOk;
}

int cmd_power_off(Client& c, const Args&, const Options& o) {
    if (!o.yes_power_off) {
        if (!isatty(STDIN_FILENO))
            usage_error("power-off is irreversible; confirm with --yes-power-off (stdin is not a terminal)");
        std::cerr << "Powering off the vehicle is irreversible.\nType power-off to confirm: " << std::flush;
        std::string answer;
        if (!std::getline(std::cin, answer) || answer != "power-off")
            usage_error("power-off not confirmed; nothing was sent");
    }
    c.call(kRootPath, kVehicleIface, "PowerOff", append_args("s", "power-off"));
    return kExitOk;
}

} // namespace caracara::ctl
