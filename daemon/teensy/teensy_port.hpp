// The Teensy's commands (wheels, servos, LEDs, distance, Stop) over its TeensyConnection, which
// polls orientation and distances one frame per cycle and carries every frame on its worker's
// thread: a command's result comes back later (a Completion), so a slow or hung Teensy never
// holds the loop. The Turn with its Confirm handshake is its TeensyTurn's.
#pragma once

#include "core/config.hpp"
#include "core/status.hpp"
#include "daemon/loop/completion.hpp"
#include "daemon/teensy/teensy_connection.hpp"
#include "daemon/teensy/teensy_turn.hpp"
#include "daemon/interfaces/command_gate.hpp"
#include "daemon/interfaces/failsafe_gate.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "drivers/platform/device_io.hpp"
#include "drivers/platform/event_loop.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace caracara {

class TeensyPort {
public:
    // `gate`: whether the vehicle takes a wheel or turn command; `failsafes`: where the link's
    // loss is pushed (teensy-link-lost).
    TeensyPort(sd_event* event, DeviceIo& io, const SpiSettings& settings, CommandGate& gate, FailsafeGate& failsafes,
               VehicleEvents& events);
    ~TeensyPort() { close(); }

    int open() { return connection_.open(); } // 0 or -errno (before start); a missing Teensy is not fatal
    // Starts the worker; its results come back at `priority`.
    std::string start(int64_t priority) { return connection_.start(priority); }
    void close(); // after the worker's job on the wire (what was queued still runs)
    bool is_open() const { return connection_.is_open(); }
    bool link_lost() const { return connection_.link_lost(); } // gone, absent or silent; no valid frame since
    TeensyLoss loss() const { return connection_.loss(); }

    void poll() { connection_.poll(); }
    // Kill, power-off, start and exit: Stop halts the wheels and ends a running turn.
    void stop_motion();
    // The command timeout or the commanding client gone: Stop, if the wheels or a turn move.
    void stop_if_moving();
    // Ends a running turn with `r` (kill, power-off, shutdown).
    void cancel_turn(const Result& r) { turn_.cancel(r); }

    // Each returns an error at once (and never calls `done`), or {} and calls `done` (if any)
    // with the Teensy's answer once the frame is over. The LEDs are refused once powered off.
    Result set_leds(int red, int green, int blue, Completion done);
    // Wheels and turns are motors: a command from `client`, under the command timeout.
    Result set_speed(int left, int right, std::string_view client, Completion done);
    Result stop(int duty, Completion done);
    Result servo(int id, int degrees, Completion done);
    using DistanceDone = std::function<void(const Result&, uint16_t mm)>;
    Result distance(int sensor, DistanceDone done);
    // Starts a Turn (relative) or Turn to (absolute); `done` runs when the Teensy confirms
    // completion, or on failure.
    Result turn(double radians, bool absolute, std::string_view client, Completion done) {
        return turn_.start(radians, absolute, client, std::move(done));
    }

    const TeensyTelemetry& telemetry() const { return connection_.telemetry(); }
    const TeensyLinkCounters& counters() const { return connection_.counters(); }
    std::array<uint8_t, 3> leds() const { return leds_; }

private:
    CommandGate& gate_;
    VehicleEvents& events_;
    TeensyConnection connection_;
    TeensyTurn turn_;
    std::array<uint8_t, 3> leds_{};
    std::optional<std::array<uint8_t, 3>> leds_out_; // handed to the worker, not answered yet
    bool wheels_moving_ = false;
};

} // namespace caracara
