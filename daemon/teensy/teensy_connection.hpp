// The connection to the Teensy over SPI: the node, the link and the TeensyWorker whose thread
// carries every frame, so a slow or hung Teensy never holds the loop. Its TeensyPoll asks one
// frame a cycle; a command's frame is handed over and its Result given back later. The link is
// lost (teensy-link-lost pushed to the failsafes, which kill) when the device goes
// away (ENODEV: its TeensyReopen asks for it again once a second), when a fitted Teensy is absent
// at start, or when no valid frame came back for [spi] silence_ms of asking (busy for ever, no
// answer, garbage); it is back at the next valid frame. The commands themselves are TeensyPort's,
// the Turn handshake TeensyTurn's.
#pragma once

#include "core/config.hpp"
#include "core/status.hpp"
#include "daemon/loop/completion.hpp"
#include "daemon/teensy/teensy_link_watch.hpp"
#include "daemon/teensy/teensy_poll.hpp"
#include "daemon/teensy/teensy_reopen.hpp"
#include "daemon/teensy/teensy_telemetry.hpp"
#include "daemon/teensy/teensy_worker.hpp"
#include "daemon/interfaces/failsafe_gate.hpp"
#include "drivers/devices/teensy_link.hpp"
#include "drivers/platform/device_io.hpp"
#include "drivers/platform/event_loop.hpp"
#include "drivers/platform/spi_dev.hpp"
#include "drivers/protocol/teensy_codec.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

namespace caracara {

class TeensyConnection {
public:
    TeensyConnection(sd_event* event, DeviceIo& io, const SpiSettings& settings, FailsafeGate& failsafes);

    // `lost`: the device went away; `back`: it is open again (the wheels are to be stopped).
    void set_handlers(std::function<void()> lost, std::function<void()> back) {
        on_lost_ = std::move(lost);
        on_back_ = std::move(back);
    }

    int open(); // 0 or -errno, on the caller's thread (before start); a missing Teensy is not fatal
    std::string start(int64_t priority); // the worker and the silence timer
    void close(); // after the worker's job on the wire (what was queued still runs)
    bool is_open() const { return open_; }
    // A command's own verdict before it takes the vehicle: its arguments' (`args`), then the
    // link's, so that a command the Teensy cannot carry makes no one the commanding client.
    Result carries(const Result& args) const {
        return !args.ok() || open_ ? args : Result{Status::LinkError, "the Teensy is not connected"};
    }
    // The link is lost (gone, absent though fitted, or silent) and no valid frame came since. A
    // Teensy not fitted that never answered is not lost.
    bool link_lost() const { return watch_.loss() != TeensyLoss::None; }
    TeensyLoss loss() const { return watch_.loss(); }

    // The cycle's poll frame (TeensyPoll), unless the last one is still out.
    void poll();
    // Hands `frame` (run on the worker, returning the link's error) over; `done` gets its Result.
    void command(std::function<teensy::TeensyError()> frame, std::string what, Completion done);

    TeensyLink& link() { return link_; } // the worker's while it runs
    TeensyWorker& worker() { return worker_; }
    TeensyTelemetry& telemetry() { return tm_; }
    const TeensyTelemetry& telemetry() const { return tm_; }
    const TeensyLinkCounters& counters() const { return worker_.counters(); }

private:
    void polled(TeensyPoll::Outcome outcome);
    // The SPI device went away (ENODEV: unbound, a restarted simulator): closed, teensy-link-lost
    // pushed (the wheels cannot be stopped: the failsafes kill), and asked for again once a second.
    void lose_link();
    // The link lost for `why` (teensy-link-lost pushed: the kill, at once), unless it already is.
    void lose(TeensyLoss why, std::string_view what);
    int io_errno(teensy::TeensyError e) const; // the worker's: the failed transfer's errno, or 0
    // A valid frame came back (`now`): a lost link is back.
    void heard(uint64_t now);
    // The device opened again after it was gone or absent.
    void reopened();

    sd_event* event_;
    FailsafeGate& failsafes_;
    SpiDev spi_;      // the worker's while it runs
    TeensyLink link_; // the worker's while it runs
    TeensyWorker worker_;
    bool open_ = false; // loop thread: the SPI node is open (as far as the loop knows)
    TeensyLinkWatch watch_; // loop thread
    TeensyTelemetry tm_;
    TeensyPoll poll_;
    TeensyReopen reopen_;
    std::function<void()> on_lost_;
    std::function<void()> on_back_;
};

} // namespace caracara
