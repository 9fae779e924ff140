#include "tools/caracaractl/teensy_commands.hpp"

#include <iostream>

namespace caracara::ctl {

namespace {

// Turn and TurnTo reply only when the Teensy reports the turn finished.
constexpr uint64_t kTurnTimeoutUsec = 60'000'000;

} // namespace

int cmd_turn(Client& c, const Args& a, const Options&) {
    c.call(kTeensyPath, kTeensyIface, "Turn", append_args("d", parse_double(a[0], "RAD")), kTurnTimeoutUsec);
    return kExitOk;
}

int cmd_turn_to(Client& c, const Args& a, const Options&) {
    c.call(kTeensyPath, kTeensyIface, "TurnTo", append_args("d", parse_double(a[0], "RAD")), kTurnTimeoutUsec);
    return kExitOk;
}

int cmd_servo(Client& c, const Args& a, const Options&) {
    const uint8_t id = parse_byte(a[0], "ID"), degrees = parse_byte(a[1], "DEG");
    c.call(kTeensyPath, kTeensyIface, "SetServo", append_args("yy", id, degrees));
    return kExitOk;
}

int cmd_distance(Client& c, const Args& a, const Options&) {
    auto reply = c.call(kTeensyPath, kTeensyIface, "GetDistance", append_args("y", parse_byte(a[0], "ID")));
    uint16_t mm = 0;
    if (int r = sd_bus_message_read(reply.get(), "q", &mm); r < 0)
        throw Failure{kExitRefused, "malformed GetDistance reply from caracarad"};
    std::cout << mm << " mm\n";
    return kExitOk;
}

int cmd_stop_wheels(Client& c, const Args& a, const Options&) {
    c.call(kTeensyPath, kTeensyIface, "Stop", append_args("y", parse_byte(a[0], "DUTY")));
    return kExitOk;
}

int cmd_wheels(Client& c, const Args& a, const Options&) {
    const int32_t left = parse_int(a[0], "LEFT"), right = parse_int(a[1], "RIGHT");
    c.call(kTeensyPath, kTeensyIface, "SetSpeed", append_args("ii", left, right));
    return kExitOk;
}

} // namespace caracara::ctl
