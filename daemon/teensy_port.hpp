// The SPI link to the Teensy: polling orientation and distances one frame per cycle, its
// commands (wheels, servos, LEDs, distance), and the Turn with its Confirm handshake, which
// runs on a timer of its own so the loop never waits for a turn to finish. Every frame is
// carried by the TeensyWorker's thread: a command's result comes back later (a Completion), so
// a slow or hung Teensy never holds the loop.
#pragma once

#include "core/config.hpp"
#include "core/status.hpp"
#include "daemon/command_gate.hpp"
#include "daemon/completion.hpp"
#include "daemon/teensy_worker.hpp"
#include "daemon/vehicle_events.hpp"
#include "drivers/devices/teensy_link.hpp"
#include "drivers/platform/device_io.hpp"
#include "drivers/platform/event_loop.hpp"
#include "drivers/platform/spi_dev.hpp"
#include "drivers/protocol/teensy_codec.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
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

    int open(); // 0 or -errno, on the caller's thread (before start); a missing Teensy is not fatal
    // Starts the worker; its results come back at `priority`.
    std::string start(int64_t priority) { return worker_.start(event_, priority); }
    void close(); // after the worker's job on the wire (what was queued still runs)
    bool is_open() const { return open_; }

    // One frame: the three orientation axes, then one distance sensor, in turn; handed to the
    // worker unless the last one is still out (a slow Teensy is polled as fast as it answers).
    void poll();
    // Kill, power-off, start and exit: Stop halts the wheels and ends a running turn.
    void stop_motion();
    // The command timeout or the commanding client gone: Stop, if the wheels or a turn move.
    void stop_if_moving();
    // Ends a running turn with `r` (kill, power-off, shutdown).
    void cancel_turn(const Result& r);

    // Each returns an error at once (and never calls `done`), or {} and calls `done` (if any)
    // with the Teensy's answer once the frame is over.
    Result set_leds(int red, int green, int blue, Completion done);
    // Wheels and turns are motors: a command from `client`, under the command timeout.
    Result set_speed(int left, int right, std::string_view client, Completion done);
    Result stop(int duty, Completion done);
    Result servo(int id, int degrees, Completion done);
    using DistanceDone = std::function<void(const Result&, uint16_t mm)>;
    Result distance(int sensor, DistanceDone done);
    // Starts a Turn (relative) or Turn to (absolute); `done` runs when the Teensy confirms
    // completion, or on failure.
    Result turn(double radians, bool absolute, std::string_view client, Completion done);

    const TeensyTelemetry& telemetry() const { return tm_; }
    const TeensyLinkCounters& counters() const { return worker_.counters(); }
    std::array<uint8_t, 3> leds() const { return leds_; }

private:
    struct PollResult {
        unsigned slot = 0;
        unsigned sensor = 0;
        bool ok = false;
        double value = 0;
        int err = 0;
    };
    static int on_turn_step(sd_event_source*, uint64_t usec, void* userdata);
    static int on_reopen(sd_event_source*, uint64_t usec, void* userdata);
    // Hands `frame` (run on the worker, returning the link's error) over; `done` gets its Result.
    void command(std::function<teensy::TeensyError()> frame, std::string what, Completion done);
    void poll_done();
    // The SPI device went away (ENODEV: unbound, a restarted simulator): closed, the vehicle
    // killed (the wheels cannot be stopped), and asked for again once a second.
    void link_lost();
    void schedule_reopen();
    void turn_step();
    void finish_turn(const Result& r);

    sd_event* event_;
    CommandGate& gate_;
    VehicleEvents& events_;
    SpiDev spi_;   // the worker's while it runs
    TeensyLink link_; // the worker's while it runs
    TeensyWorker worker_;
    bool open_ = false; // loop thread: the SPI node is open (as far as the loop knows)
    TeensyTelemetry tm_;
    std::array<uint8_t, 3> leds_{};
    std::optional<std::array<uint8_t, 3>> leds_out_; // handed to the worker, not answered yet
    bool wheels_moving_ = false;
    unsigned poll_index_ = 0;
    bool poll_out_ = false;
    PollResult poll_;  // the worker's while a poll is out
    teensy::ConfirmHandshake handshake_; // the worker's while a step is out
    teensy::ConfirmHandshake::Step step_;
    uint64_t turn_id_ = 0; // a step's result for a turn that ended meanwhile is dropped
    Completion turn_done_;
    SourcePtr turn_source_;
    SourcePtr reopen_timer_;
};

} // namespace caracara
