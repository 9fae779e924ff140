// The preflight (docs/commissioning.md): one go/no-go table before a dive. It watches for a
// window (the Teensy's orientation must change, as a live sensor's does; each thruster must
// answer its status reads) on a timer it owns, so the loop is never held, then judges every item
// (PreflightChecks) and answers every caller that asked meanwhile. Read only: it orders nothing
// and changes nothing.
#pragma once

#include "core/config.hpp"
#include "core/preflight_row.hpp"
#include "daemon/commissioning/preflight_checks.hpp"
#include "daemon/loop/completion.hpp"
#include "daemon/loop/deadline_timer.hpp"
#include "daemon/teensy/teensy_port.hpp"
#include "drivers/platform/event_loop.hpp"

#include <array>
#include <string>
#include <vector>

namespace caracara {

class Preflight final {
public:
    // The window: at least a second (50 orientation answers and six status reads per thruster at
    // 50 Hz), and at least three rounds of status reads at a slower loop (window_ns()).
    static constexpr uint64_t kMinWindowNs = 1'000'000'000;
    static constexpr uint64_t kStatusRounds = 3;

    Preflight(const DaemonConfig& config, const ThrusterBus& bus, const TeensyPort& teensy, const SafetyLines& lines);
    std::string start(sd_event* event); // the window's timer; "" or why it could not be made
    void stop();
    void set_config_file(std::string path) { checks_.set_config_file(std::move(path)); }

    // `done` gets Ok with rows() filled once the window is over; a call during a window joins it.
    void run(Completion done);
    const std::vector<PreflightRow>& rows() const { return rows_; }
    // Every row go.
    bool all_go() const;

private:
    uint64_t window_ns() const;
    void finish();
    PreflightRow teensy_row() const;

    const DaemonConfig& config_;
    const ThrusterBus& bus_;
    const TeensyPort& teensy_;
    PreflightChecks checks_;
    DeadlineTimer timer_;
    std::vector<Completion> waiting_;
    std::vector<ThrusterCounters> before_;
    std::array<double, 3> orientation_before_{};
    std::vector<PreflightRow> rows_;
};

} // namespace caracara
