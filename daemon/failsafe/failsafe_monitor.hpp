// The failsafes at work: every thruster's last status reply and the vehicle's own conditions go
// into the FailsafePolicy (core/failsafe_policy) on this object's own timer, and at once when
// the Vehicle says one changed (the last pilot left, the Teensy link went: FailsafeGate);
// what the policy raises is carried out by the Vehicle (exclude, kill; a surface by the
// FailsafeAscent) and told everywhere by the FailsafeReport (VehicleEvents: D-Bus, the dive
// recorder, STATUS=; the journal, one line per transition).
#pragma once

#include "core/failsafe_policy.hpp"
#include "daemon/failsafe/failsafe_ascent.hpp"
#include "daemon/interfaces/failsafe_gate.hpp"
#include "daemon/failsafe/failsafe_reading.hpp"
#include "daemon/failsafe/failsafe_report.hpp"
#include "daemon/vehicle/vehicle.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "drivers/platform/event_loop.hpp"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace caracara {

class FailsafeMonitor final : public FailsafeGate {
public:
    using Readings = std::function<std::optional<FailsafeReading>(std::size_t thruster)>;
    // Which of the vehicle's own (fixed) conditions hold now. Bus lost, an unreachable thruster
    // and an unreadable kill switch kill where they arise and are told here; pilot lost and the
    // Teensy link lost are killed for here.
    using Conditions = std::function<std::array<bool, kFailsafeConditionCount>()>;
    // Readings at 20 Hz: a status reply comes every (thrusters / status reads per tick) cycles,
    // 160 ms for eight at 50 Hz, so a persistence time is kept to within one period. Faster
    // when the command timeout is shorter than two periods: the ascent is re-sent at each one.
    static constexpr uint64_t kPeriodNs = 50'000'000;

    // The vehicle's FailsafeGate from here on, so that no condition it tells is lost.
    FailsafeMonitor(sd_event* event, const FailsafeSettings& settings, std::size_t thrusters, Readings readings,
                    Conditions conditions, Vehicle& vehicle, VehicleEvents& events);
    ~FailsafeMonitor() override { vehicle_.set_failsafe_gate(nullptr); }
    FailsafeMonitor(const FailsafeMonitor&) = delete;
    FailsafeMonitor& operator=(const FailsafeMonitor&) = delete;
    std::string start(); // "" or why the timer could not be made
    void stop() { timer_.reset(); }

    Result clear_kill_refusal() const override;
    void conditions_changed() override;
    // ClearKill for a pilot who means it: the named condition's failsafes warn until it clears.
    Result clear_kill_override(std::string_view condition, std::string_view caller);

    const std::vector<ActiveFailsafe>& active() const { return policy_.active(); }
    const FailsafeSettings& settings() const { return settings_; }
    // When the running ascent ends with its kill (CLOCK_MONOTONIC ns); 0 when none runs.
    uint64_t surfacing_until() const { return ascent_.until(); }
    // When the pilot-lost failsafe kills (CLOCK_MONOTONIC ns) while the last pilot is gone and
    // its persistence runs; 0 otherwise. A change is announced with the failsafes.
    uint64_t pilot_lost_kill_at() const { return pilot_lost_kill_at_; }
    // "water-detect surface thruster 3, overtemp exclude thruster 2" ("" when none).
    std::string summary() const;

    // Runs one reading of every thruster and the persistence timers (the timer calls it).
    void poll(uint64_t now);

private:
    static int on_timer(sd_event_source* s, uint64_t usec, void* userdata);
    // The vehicle's own conditions into the policy, and what has held for its persistence time.
    FailsafeTransitions look_at_conditions(uint64_t now);
    void carry_out(const FailsafeTransitions& ts, uint64_t now);

    sd_event* event_;
    const FailsafeSettings& settings_;
    std::size_t thrusters_;
    Readings readings_;
    Conditions conditions_;
    Vehicle& vehicle_;
    VehicleEvents& events_;
    FailsafePolicy policy_;
    FailsafeReport report_;
    FailsafeAscent ascent_;
    SourcePtr timer_;
    uint64_t period_us_;
    std::array<bool, kMotorCount> excluded_{};
    std::array<std::optional<FailsafeReading>, kMotorCount> observed_{}; // each thruster's reading last observed
    std::optional<FailsafeCondition> overriding_; // set aside during ClearKillOverride's ClearKill
    uint64_t pilot_lost_kill_at_ = 0;
};

} // namespace caracara
