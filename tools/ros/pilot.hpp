// One remote DDS writer's own connection to caracarad: each writer of a command topic is a
// pilot, so the daemon's per-client rules hold per writer (its thrust goes to zero when this
// connection closes; the command timeout, which is the vehicle's, zeroes it when it stops
// sending). Calls are sent asynchronously and in order; a refusal is logged with the daemon's
// error name and counted in the CommandRecord (/diagnostics).
#pragma once

#include "drivers/sdbus/sdbus.hpp"
#include "tools/ros/command_record.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace caracara::ros {

class Pilot {
public:
    // Connects at once and attaches to `event`; throws std::runtime_error when it cannot.
    // `motion_note` goes with a refused SetMotion in the log (what its axes are in the command's terms).
    // `writer`: the DDS writer's GID as `ros2 topic info -v` prints it.
    Pilot(sd_event* event, const caracara::dbus::BusChoice& bus, std::string writer, CommandRecord& record,
          std::string motion_note = "");
    ~Pilot();
    Pilot(const Pilot&) = delete;
    Pilot& operator=(const Pilot&) = delete;

    void set_motion(const std::array<double, 6>& axes);
    void set_thrust(const std::vector<int32_t>& values);

private:
    static int on_motion_reply(sd_bus_message* m, void* userdata, sd_bus_error* error);
    static int on_thrust_reply(sd_bus_message* m, void* userdata, sd_bus_error* error);
    void replied(sd_bus_message* m, const std::string& writer);
    void send(caracara::dbus::MessagePtr call, const char* what, sd_bus_message_handler_t reply);

    std::string writer_, motion_writer_;
    CommandRecord& record_;
    caracara::dbus::BusPtr bus_;
};

} // namespace caracara::ros
