// The vehicle's safety lines: the kill switch (its KillSwitch, whose edges wake the loop above
// D-Bus and the bus work), the kill output and the power-off output. It reads and drives
// lines; what a switch change means is the Vehicle's business. A switch that cannot be read is
// a pressed one until it can be again; it and an output that cannot be written are pushed to
// the failsafes (kill-switch-unreadable, safety-line-lost); a line gone is asked for once a second.
#pragma once

#include "core/config.hpp"
#include "daemon/interfaces/failsafe_gate.hpp"
#include "daemon/safety/kill_switch.hpp"
#include "drivers/devices/kill_output_watcher.hpp"
#include "drivers/platform/event_loop.hpp"
#include "drivers/platform/gpio_backend.hpp"

#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace caracara {

class SafetyLines {
public:
    class Listener {
    public:
        virtual ~Listener() = default;
        // The switch's current reading (set = kill), on every edge and every backstop poll.
        virtual void kill_switch_read(bool set) = 0;
    };

    SafetyLines(sd_event* event, GpioBackend& gpio, const GpioSettings& settings, FailsafeGate& failsafes)
        : event_(event), gpio_(gpio), settings_(settings), failsafes_(failsafes),
          kill_switch_(event, gpio, settings.kill_switch, [this] { poll(); }, [this](const std::string&) { switch_lost(); }) {}

    // Requests the configured lines (the kill output starting at `kill_asserted`) and watches
    // the switch's edges. "" or what could not be had.
    std::string open(bool kill_asserted, Listener* listener);
    void close();

    // Reads the switch and reports it (a backstop for a lost edge event); reads the outputs back
    // now and then, since an output that went away has no event to say so.
    void poll();
    void set_kill_output(bool asserted);
    bool has_power_off() const { return power_off_ != nullptr; }
    // A kill output is configured but its line went away (asked for again once a second).
    bool kill_output_missing() const { return settings_.kill_output && !kill_out_; }
    // A configured output (kill, power-off) went away and is not back yet.
    bool output_missing() const { return kill_output_missing() || (settings_.power_off_output && !power_off_); }
    void assert_power_off();
    // Told the kill output line whenever it changes (null before it goes): the fatal-signal
    // emergency stop writes it first.
    void set_kill_output_watcher(KillOutputWatcher* watcher) {
        kill_output_watcher_ = watcher;
        kill_output_changed();
    }
    // A configured switch that cannot be read now (it counts as set meanwhile).
    bool kill_switch_unreadable() const { return kill_switch_.unreadable(); }
    // The preflight's view: the switch's level (set = kill) and the kill output read back from
    // its line, nullopt when unconfigured or unreadable; what the kill output should show.
    bool kill_switch_configured() const { return settings_.kill_switch.has_value(); }
    std::optional<bool> kill_switch_level() const { return kill_switch_.level(); }
    bool kill_output_configured() const { return settings_.kill_output.has_value(); }
    std::optional<bool> kill_output_readback() const {
        const int v = kill_out_ ? kill_out_->get() : -1;
        return v < 0 ? std::nullopt : std::optional<bool>(v == 1);
    }
    bool kill_output_intended() const { return kill_asserted_; }
    // The switch's event fd (for the loop's "is anything waiting" check), or -1.
    int kill_switch_fd() const { return kill_switch_.fd(); }

private:
    static int on_reopen(sd_event_source*, uint64_t usec, void* userdata);
    // An output (kill, power-off) could not be written: dropped, safety-line-lost pushed, and
    // asked for again with the reopen timer (the kill output then starts asserted).
    void output_lost(std::unique_ptr<GpioLine>& line, const char* what, int err);
    void schedule_reopen();
    // Every kOutputCheckUs: an output that cannot be read back went away (output_lost).
    void check_outputs();
    // The switch cannot be read (its chip or the simulator went away): it counts as set (a
    // kill), kill-switch-unreadable is pushed, and it is asked for again once a second.
    void switch_lost();

    sd_event* event_;
    GpioBackend& gpio_;
    const GpioSettings& settings_;
    FailsafeGate& failsafes_;
    Listener* listener_ = nullptr;
    KillSwitch kill_switch_;
    std::unique_ptr<GpioLine> kill_out_;
    std::unique_ptr<GpioLine> power_off_;
    SourcePtr reopen_timer_;
    bool kill_asserted_ = true; // what the kill output should show (for a reopened line)
    uint64_t next_output_check_us_ = 0;
    KillOutputWatcher* kill_output_watcher_ = nullptr;
    void kill_output_changed() {
        if (kill_output_watcher_)
            kill_output_watcher_->set_kill_output(kill_out_.get());
    }
};

} // namespace caracara
