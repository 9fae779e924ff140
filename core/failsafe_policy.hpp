// The failsafe policy: conditions in, actions out, with time. Pure logic (the daemon's
// FailsafeMonitor feeds it each thruster status reply and its timer, and the Vehicle carries
// out what it decides), so persistence, clearing and priorities are unit-tested.
//
//   absent ──reading shows it──> pending ──held persistence_ms──> active (raised: its action)
//   pending/active ──reading shows it gone (the clearing rule)──> absent (an active one: cleared)
//
// When several failsafes are active the most severe action wins (kill > surface > exclude >
// warn); exclusions are per thruster and add up. A failsafe a pilot overrode
// (ClearKillOverride) only warns until its condition clears.
#pragma once

#include "core/failsafe.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

namespace caracara {

struct ActiveFailsafe {
    FailsafeCondition condition = FailsafeCondition::WaterDetect;
    FailsafeAction action = FailsafeAction::Warn; // as configured, even when overridden
    int thruster = -1;                            // -1: the vehicle's, not one thruster's
    bool overridden = false;
    // What it does now: an overridden one warns.
    FailsafeAction effective() const { return overridden ? FailsafeAction::Warn : action; }
    bool operator==(const ActiveFailsafe&) const = default;
};

struct FailsafeTransition {
    ActiveFailsafe failsafe;
    bool raised = true; // false: its condition cleared
    bool operator==(const FailsafeTransition&) const = default;
};
using FailsafeTransitions = std::vector<FailsafeTransition>;

class FailsafePolicy {
public:
    static constexpr uint64_t kNoDeadline = std::numeric_limits<uint64_t>::max();

    FailsafePolicy(const FailsafeSettings& settings, std::size_t thrusters);

    // A good status reply from thruster i: its FAULT bits (SeaBotix IDS 8.4.2 word 2; the legacy
    // STATUS bits 0-4 are in the same places) and TEMPERATURE when the reply has one.
    FailsafeTransitions observe(std::size_t thruster, uint8_t fault_bits, std::optional<uint8_t> temperature_c,
                                uint64_t now);
    // A condition of the vehicle's own (the fixed ones).
    FailsafeTransitions set_condition(FailsafeCondition c, bool holds, uint64_t now);
    // Raises what has held for its persistence time; call at next_deadline().
    FailsafeTransitions tick(uint64_t now);
    uint64_t next_deadline() const;
    // When a condition of the vehicle's own that holds but is not yet active raises its failsafe
    // (its start and persistence); kNoDeadline when it does not hold, or already raised.
    uint64_t pending_deadline(FailsafeCondition c) const;

    // The active failsafes, in the order they were raised.
    const std::vector<ActiveFailsafe>& active() const { return active_; }
    // The most severe action in force, or nullopt when none is active.
    std::optional<FailsafeAction> strongest() const;
    bool excluded(std::size_t thruster) const;
    // Active failsafes that stop a ClearKill (kill or surface, not overridden).
    std::vector<ActiveFailsafe> blocking() const;
    // The active kill and surface failsafes of `c` warn from now on, until their condition
    // clears (an exclusion stays). The number of failsafes overridden.
    std::size_t override_condition(FailsafeCondition c);

private:
    struct Tracked {
        bool present = false;
        uint64_t since = 0;
        bool active = false;
    };
    void update(int thruster, FailsafeCondition c, bool present, uint64_t now, FailsafeTransitions& out);
    Tracked& tracked(int thruster, FailsafeCondition c);
    bool overtemp(const Tracked& t, uint8_t bits, std::optional<uint8_t> temperature_c) const;

    FailsafeSettings settings_;
    // One row per thruster, and a last one for the vehicle's own conditions.
    std::vector<std::array<Tracked, kFailsafeConditionCount>> rows_;
    std::vector<ActiveFailsafe> active_;
};

} // namespace caracara
