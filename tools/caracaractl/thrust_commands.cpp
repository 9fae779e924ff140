#include "tools/caracaractl/thrust_commands.hpp"

#include "tools/caracaractl/render.hpp"

namespace caracara::ctl {

namespace {

// Packet words 8 and 9: killState and powerOffState.
constexpr size_t kPacketKillWord = 8, kPacketPowerOffWord = 9;

} // namespace

int cmd_thrust(Client& c, const Args& a, const Options& o) {
    const std::vector<int32_t> values = parse_ints(a, "motor value");
    return hold_command(c, "SetThrust", int_array(values), "SetThrust(" + int_list(values) + ")", o.hold);
}

int cmd_motion(Client& c, const Args& a, const Options& o) {
    const char* names[] = {"X", "Y", "Z", "YAW", "PITCH", "ROLL"};
    double v[6];
    for (size_t i = 0; i < 6; ++i)
        v[i] = parse_double(a[i], names[i]);
    return hold_command(c, "SetMotion", append_args("dddddd", v[0], v[1], v[2], v[3], v[4], v[5]),
                        strf("SetMotion(%g, %g, %g, %g, %g, %g)", v[0], v[1], v[2], v[3], v[4], v[5]), o.hold);
}

int cmd_packet(Client& c, const Args& a, const Options& o) {
    const std::vector<int32_t> words = parse_ints(a, "packet word");
    HoldOptions hold = o.hold;
    // A kill latches and a power-off is final: there is nothing to keep alive, and a repeated
    // power-off would only be refused.
    if (words[kPacketKillWord] != 0 || words[kPacketPowerOffWord] != 0)
        hold = HoldOptions{true, 0};
    return hold_command(c, "ApplyPacket", int_array(words), "ApplyPacket(" + int_list(words) + ")", hold);
}

} // namespace caracara::ctl
