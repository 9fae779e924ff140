#include "daemon/commissioning/preflight.hpp"

#include "core/clock.hpp"

#include <algorithm>
#include <cstdio>
#include <utility>

namespace caracara {

Preflight::Preflight(const DaemonConfig& config, const ThrusterBus& bus, const TeensyPort& teensy,
                     const SafetyLines& lines)
    : config_(config), bus_(bus), teensy_(teensy), checks_(config, bus, lines), timer_([this] { finish(); }) {}

std::string Preflight::start(sd_event* event) { return timer_.start(event); }

void Preflight::stop() {
    timer_.stop();
    rows_.clear();
    for (Completion& done : std::exchange(waiting_, {}))
        done({Status::Busy, "caracarad is stopping"});
}

void Preflight::run(Completion done) {
    waiting_.push_back(std::move(done));
    if (waiting_.size() > 1)
        return; // joins the window under way
    before_.clear();
    for (std::size_t i = 0; i < bus_.size(); ++i)
        before_.push_back(bus_.thruster(i).counters());
    orientation_before_ = teensy_.telemetry().orientation;
    timer_.arm(monotonic_ns() + window_ns());
}

uint64_t Preflight::window_ns() const {
    const ControlSettings& c = config_.control;
    if (c.loop_rate_hz == 0) // as fast as the bus allows
        return kMinWindowNs;
    const uint64_t ticks_per_round = (bus_.size() + c.status_reads_per_tick - 1) / c.status_reads_per_tick;
    return std::max(kMinWindowNs, kStatusRounds * ticks_per_round * 1'000'000'000 / c.loop_rate_hz);
}

bool Preflight::all_go() const {
    return std::all_of(rows_.begin(), rows_.end(), [](const PreflightRow& r) { return r.go; });
}

PreflightRow Preflight::teensy_row() const {
    PreflightRow r{PreflightItem::Teensy, -1, false, {}, {}};
    const TeensyTelemetry& tm = teensy_.telemetry();
    if (!config_.spi.fitted && !tm.online) {
        r.go = true;
        r.observed = "not fitted (spi.fitted = false)";
        return r;
    }
    if (teensy_.link_lost() || !tm.online) {
        r.observed = "offline (" + std::string(name_of(teensy_.loss())) + ") on " + config_.spi.device;
        r.advice = "check the Teensy's power, its SPI cable and its firmware";
        return r;
    }
    char att[96];
    std::snprintf(att, sizeof att, "yaw %+.4f pitch %+.4f roll %+.4f rad", tm.orientation[0], tm.orientation[1],
                  tm.orientation[2]);
    if (tm.orientation == orientation_before_) {
        r.observed = std::string("online, orientation frozen at ") + att + " over the window";
        r.advice = "the orientation sensor repeats one reading: check the IMU and the Teensy firmware";
        return r;
    }
    r.go = true;
    r.observed = std::string("online, orientation changing (") + att + ")";
    return r;
}

void Preflight::finish() {
    rows_.clear();
    for (std::size_t i = 0; i < bus_.size(); ++i)
        rows_.push_back(checks_.thruster(i, before_[i]));
    rows_.push_back(checks_.bus());
    rows_.push_back(teensy_row());
    rows_.push_back(checks_.kill_switch());
    rows_.push_back(checks_.kill_output());
    rows_.push_back(checks_.config());
    rows_.push_back(checks_.recorder());
    rows_.push_back(checks_.failsafes());
    rows_.push_back(checks_.clock());
    for (Completion& done : std::exchange(waiting_, {}))
        done({});
}

} // namespace caracara
