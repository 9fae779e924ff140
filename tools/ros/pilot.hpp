// One remote DDS writer's own connection to caracarad: each writer of a command topic is a
// pilot, so the daemon's per-client rules hold per writer (its thrust goes to zero when this
// connection closes, the command timeout runs per client). Calls are sent asynchronously and in
// order; a refusal is logged with the daemon's error name.
#pragma once

#include "drivers/sdbus/sdbus.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace caracara::ros {

class Pilot {
public:
    // Connects at once and attaches to `event`; throws std::runtime_error when it cannot.
    // `motion_note` goes with a refused SetMotion in the log (what its axes are in the command's terms).
    Pilot(sd_event* event, const caracara::dbus::BusChoice& bus, std::string writer, std::string motion_note = "");
    ~Pilot();
    Pilot(const Pilot&) = delete;
    Pilot& operator=(const Pilot&) = delete;

    void set_motion(const std::array<double, 6>& axes);
    void set_thrust(const std::vector<int32_t>& values);

private:
    static int on_reply(sd_bus_message* m, void* userdata, sd_bus_error* error);
    void send(caracara::dbus::MessagePtr call, const char* what, const std::string& writer);

    std::string writer_, motion_writer_;
    caracara::dbus::BusPtr bus_;
};

} // namespace caracara::ros
