// The failsafes at work, and the one automatic caller of Vehicle::kill: every thruster's last
// status reply goes into the FailsafePolicy (core/failsafe_policy) on this object's own timer,
// and each fixed condition at once when its source pushes it (FailsafeGate::push: the bus
// loss, thruster health, the safety lines, the Teensy connection, the pilot watch; the rows of
// core/failsafe.hpp's kFailsafeTable). What the policy raises is carried out here (exclude; a
// kill with the row's kill source; a surface by the FailsafeAscent) and told everywhere by
// the FailsafeReport (VehicleEvents: D-Bus, the dive recorder, STATUS=; the journal, one line
// per transition). A push that comes while a kill is carried out (this object's, or another of
// the Vehicle's sequences: the kill output lost as it is asserted) is decided right after it,
// never halfway through it; one that clears during this object's own kill, at the next reading.
#pragma once

#include "core/failsafe_policy.hpp"
#include "daemon/failsafe/failsafe_ascent.hpp"
#include "daemon/failsafe/failsafe_clearance.hpp"
#include "daemon/interfaces/failsafe_gate.hpp"
#include "daemon/failsafe/failsafe_reading.hpp"
#include "daemon/failsafe/failsafe_report.hpp"
#include "daemon/vehicle/vehicle.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "drivers/platform/event_loop.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace caracara {

class FailsafeMonitor final : public FailsafeGate {
public:
    using Readings = std::function<std::optional<FailsafeReading>(std::size_t thruster)>;
    // Readings at 20 Hz: a status reply comes every (thrusters / status reads per tick) cycles,
    // 160 ms for eight at 50 Hz, so a persistence time is kept to within one period. Faster
    // when the command timeout is shorter than two periods: the ascent is re-sent at each one.
    static constexpr uint64_t kPeriodNs = 50'000'000;

    FailsafeMonitor(sd_event* event, const FailsafeSettings& settings, std::size_t thrusters, Readings readings,
                    Vehicle& vehicle, VehicleEvents& events);
    FailsafeMonitor(const FailsafeMonitor&) = delete;
    FailsafeMonitor& operator=(const FailsafeMonitor&) = delete;
    // "" or why the timer could not be made. What was pushed before (a fitted Teensy absent at
    // start) is decided here, not at the first reading.
    std::string start();
    void stop() { timer_.reset(); }

    Result clear_kill_refusal() const override { return clearance_.refusal(); }
    void push(FailsafeCondition c, bool holds, std::string_view reason) override;
    // ClearKill for a pilot who means it: the named condition's failsafes warn until it clears.
    Result clear_kill_override(std::string_view condition, std::string_view caller) {
        return clearance_.clear_kill_override(condition, caller);
    }

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
    struct Pushed {
        FailsafeCondition condition;
        bool holds;
    };
    static int on_timer(sd_event_source* s, uint64_t usec, void* userdata);
    static int on_deferred(sd_event_source* s, void* userdata);
    // The re-entrancy guard: `ts` and every push waiting decided, what has held for its
    // persistence time raised, and carried out; a push that comes meanwhile waits (push()).
    // `keep_ascent`: the ascent's reading too (the timer's).
    void decide(FailsafeTransitions ts, uint64_t now, bool keep_ascent);
    void carry_out(const FailsafeTransitions& ts, uint64_t now);

    sd_event* event_;
    const FailsafeSettings& settings_;
    std::size_t thrusters_;
    Readings readings_;
    Vehicle& vehicle_;
    VehicleEvents& events_;
    FailsafePolicy policy_;
    FailsafeReport report_;
    FailsafeAscent ascent_;
    FailsafeClearance clearance_;
    SourcePtr timer_;
    SourcePtr deferred_; // a push inside the Vehicle's own sequence, decided right after it
    uint64_t period_us_;
    bool started_ = false;
    bool deciding_ = false;
    std::vector<Pushed> pushed_;                                // waiting for decide()
    std::array<std::string, kFailsafeConditionCount> reasons_{}; // each condition's last pushed reason
    std::array<bool, kMotorCount> excluded_{};
    std::array<std::optional<FailsafeReading>, kMotorCount> observed_{}; // each thruster's reading last observed
    uint64_t pilot_lost_kill_at_ = 0;
};

} // namespace caracara
