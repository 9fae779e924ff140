// The SPI link to the Teensy: polling orientation and distances one frame per cycle, its
// commands (wheels, servos, LEDs, distance), and the Turn with its Confirm handshake, which
// runs on a timer of its own so the loop never waits for a turn to finish.
#pragma once

#include "core/config.hpp"
#include "core/status.hpp"
#include "daemon/command_gate.hpp"
#include "daemon/completion.hpp"
#include "daemon/vehicle_events.hpp"
#include "drivers/devices/teensy_link.hpp"
#include "drivers/platform/device_io.hpp"
#include "drivers/platform/event_loop.hpp"
#include "drivers/platform/spi_dev.hpp"
#include "drivers/protocol/teensy_codec.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <string_view>
#include <vector>

namespace caracara {

struct TeensyTelemetry {
    bool online = false;
    std::array<double, 3> orientation{}; // yaw, pitch, roll
    std::vector<uint16_t> distances;
    std::vector<uint8_t> servos;
    bool turning = false;
};

class TeensyPort {
public:
    TeensyPort(sd_event* event, DeviceIo& io, const SpiSettings& settings, CommandGate& gate, VehicleEvents& events);
    ~TeensyPort() { close(); }

    int open(); // 0 or -errno; a missing Teensy is not fatal to the daemon
    void close();
    bool is_open() const { return spi_.is_open(); }

    // One frame: the three orientation axes, then one distance sensor, in turn.
    void poll();
    // Kill, power-off, start and exit: Stop halts the wheels and ends a running turn.
    void stop_motion();
    // The command timeout or the commanding client gone: Stop, if the wheels or a turn move.
    void stop_if_moving();
    // Ends a running turn with `r` (kill, power-off, shutdown).
    void cancel_turn(const Result& r);

    Result set_leds(int red, int green, int blue);
    // Wheels and turns are motors: a command from `client`, under the command timeout.
    Result set_speed(int left, int right, std::string_view client);
    Result stop(int duty);
    Result servo(int id, int degrees);
    Result distance(int sensor, uint16_t& mm);
    // Starts a Turn (relative) or Turn to (absolute); `done` runs when the Teensy confirms
    // completion, or on failure. Returns an error at once if it cannot start.
    Result turn(double radians, bool absolute, std::string_view client, Completion done);

    const TeensyTelemetry& telemetry() const { return tm_; }
    const TeensyLinkCounters& counters() const { return link_.counters(); }
    std::array<uint8_t, 3> leds() const { return leds_; }

private:
    static int on_turn_step(sd_event_source*, uint64_t usec, void* userdata);
    static int on_reopen(sd_event_source*, uint64_t usec, void* userdata);
    // The SPI device went away (ENODEV: unbound, a restarted simulator): closed, the vehicle
    // killed (the wheels cannot be stopped), and asked for again once a second.
    void link_lost();
    void schedule_reopen();
    void turn_step();
    void finish_turn(const Result& r);

    sd_event* event_;
    CommandGate& gate_;
    VehicleEvents& events_;
    SpiDev spi_;
    TeensyLink link_;
    TeensyTelemetry tm_;
    std::array<uint8_t, 3> leds_{};
    bool wheels_moving_ = false;
    unsigned poll_index_ = 0;
    teensy::ConfirmHandshake handshake_;
    Completion turn_done_;
    SourcePtr turn_source_;
    SourcePtr reopen_timer_;
};

} // namespace caracara
