#include "tools/caracaractl/thrust_commands.hpp"

#include "tools/caracaractl/render.hpp"

#include "core/frames.hpp"

#include <algorithm>
#include <optional>
#include <set>

namespace caracara::ctl {

namespace {

// Packet words 8 and 9: killState and powerOffState.
constexpr size_t kPacketKillWord = 8, kPacketPowerOffWord = 9;

} // namespace

int cmd_thrust(Client& c, const Args& a, const Options& o) {
    const std::vector<int32_t> values = parse_ints(a, "motor value");
    return hold_command(c, "SetThrust", int_array(values), "SetThrust(" + int_list(values) + ")", o.hold);
}

std::string motion_words() {
    std::string words;
    for (const auto& n : EnumNames<frames::PilotAxis>::table) {
        std::string w(n.name);
        std::replace(w.begin(), w.end(), '_', '-');
        words += (words.empty() ? "" : ", ") + w;
    }
    return words;
}

int cmd_motion(Client& c, const Args& a, const Options& o) {
    // A pilot's words (docs/frames.md), converted to the D-Bus contract's axes in core/frames and
    // nowhere else: WORD=VALUE, each word at most once, a word left out is 0.
    frames::PilotMotion m;
    std::set<frames::PilotAxis> given;
    for (const std::string& arg : a) {
        const size_t eq = arg.find('=');
        std::string word = arg.substr(0, eq == std::string::npos ? 0 : eq);
        std::replace(word.begin(), word.end(), '-', '_');
        const std::optional<frames::PilotAxis> axis = parse_name<frames::PilotAxis>(word);
        if (!axis)
            usage_error("motion takes WORD=VALUE (" + motion_words() + "), each -1..1, negative for the "
                        "opposite motion; not '" + arg + "' (docs/frames.md)");
        if (!given.insert(*axis).second)
            usage_error("motion: '" + arg.substr(0, eq) + "' given twice");
        frames::pilot_axis(m, *axis) = parse_double(arg.substr(eq + 1), arg.substr(0, eq));
    }
    const AxisDemand v = frames::from_pilot(m);
    std::string shown;
    for (const auto& n : EnumNames<frames::PilotAxis>::table)
        if (given.contains(n.value))
            shown += strf("%s%s=%g", shown.empty() ? "" : " ", n.name.data(), frames::pilot_axis(m, n.value));
    return hold_command(c, "SetMotion", append_args("dddddd", v[0], v[1], v[2], v[3], v[4], v[5]),
                        strf("SetMotion(%g, %g, %g, %g, %g, %g), the seed's axes, from %s", v[0], v[1], v[2], v[3],
                             v[4], v[5], shown.c_str()),
                        o.hold);
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
