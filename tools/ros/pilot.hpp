// One remote DDS writer's own connection to caracarad (client::PilotConnection, attached to
// caracara-ros's sd-event loop): each writer of a command topic is a
// pilot, so the daemon's per-client rules hold per writer (its thrust goes to zero when this
// connection closes; the command timeout, which is the vehicle's, zeroes it when it stops
// sending). Calls are sent asynchronously and in order; a refusal is logged with the daemon's
// error name and counted in the CommandRecord (/diagnostics).
#pragma once

#include "tools/client/pilot_connection.hpp"
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
    void replied(const client::PilotConnection::Reply& reply, const std::string& writer, const char* what);

    std::string writer_, motion_writer_;
    CommandRecord& record_;
    client::PilotConnection connection_;
};

} // namespace caracara::ros
