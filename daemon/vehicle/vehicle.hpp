// The vehicle as callers see it: the safety state machine, the commands (kill, clear,
// power-off) and who is commanding; the legacy packet is read by its PacketHandler, which asks
// the Vehicle for each of these. Whether a command is accepted is its CommandAcceptance's job
// (also the CommandGate the Teensy's wheels and turns ask); the motor commands and their values
// (requested, applied, the budget), its MotorCommands', handed out by motors(); what readers read
// (the state, who commands, the motor values), its VehicleReadings, handed out by readings();
// what the safety machine decides is carried out by its SafetyActuator (on the bus, the safety
// lines and the Teensy); the end of arming and the command timeout come from its DeadlineTimer;
// who left, its PilotWatch.
#pragma once

#include "core/config.hpp"
#include "core/mixing.hpp"
#include "core/motor_demand.hpp"
#include "core/safety.hpp"
#include "core/status.hpp"
#include "daemon/bus/thruster_bus.hpp"
#include "daemon/interfaces/failsafe_gate.hpp"
#include "daemon/loop/completion.hpp"
#include "daemon/loop/deadline_timer.hpp"
#include "daemon/safety/safety_actuator.hpp"
#include "daemon/safety/safety_lines.hpp"
#include "daemon/teensy/teensy_port.hpp"
#include "daemon/interfaces/command_gate.hpp"
#include "daemon/interfaces/demand_listener.hpp"
#include "daemon/vehicle/command_acceptance.hpp"
#include "daemon/vehicle/motor_commands.hpp"
#include "daemon/vehicle/pilot_watch.hpp"
#include "daemon/vehicle/vehicle_condition.hpp"
#include "daemon/vehicle/vehicle_readings.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "drivers/platform/event_loop.hpp"

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace caracara {

class Vehicle final : public CommandGate, public SafetyLines::Listener {
public:
    // `failsafes`: where the pilot watch pushes pilot-lost, and what a ClearKill asks last.
    Vehicle(const DaemonConfig& config, ThrusterBus& bus, SafetyLines& lines, TeensyPort& teensy,
            VehicleEvents& events, FailsafeGate& failsafes);
    // Where the motor values go down to the thrusters (the control loop).
    void set_demand_listener(DemandListener* orders) { actuator_.set_demand_listener(orders); }
    // Makes the deadline timer (end of arming, command timeout). "" or why it could not.
    std::string start(sd_event* event);
    void stop() { deadline_.stop(); }

    // The motor commands (SetThrust, SetMotion, a packet's, SetProfile, the failsafes' exclusion
    // and ascent) are its MotorCommands'.
    MotorCommands& motors() { return motors_; }
    // What readers read: the state, who commands, the motor values (VehicleReadings).
    const VehicleReadings& readings() const { return readings_; }

    Result kill(KillSource source, std::string_view reason = {});
    Result clear_kill();
    // A packet's "all clear" (killState 0): clears a kill only the packet made.
    Result clear_packet_kill() { return clear(); }
    Result power_off(std::string_view confirmation);
    // The calls that stop the thrusters hand their result to `done` once the zero orders they
    // put on the bus are on the wire (the bus worker's thread): a caller that gets it knows
    // the thrusters were told zero. The loop does not wait for them; the kill output was
    // asserted before any of them.
    void kill(KillSource source, std::string_view reason, Completion done) {
        actuator_.after_zeros(std::move(done), kill(source, reason));
    }
    void power_off(std::string_view confirmation, Completion done) {
        actuator_.after_zeros(std::move(done), power_off(confirmation));
    }
    // `done(r)` once the zeros handed to the bus so far are on the wire.
    void after_zeros(Completion done, Result r) { actuator_.after_zeros(std::move(done), std::move(r)); }
    void client_left(std::string_view unique_name) { pilots_.client_left(unique_name); }
    // Once per cycle: arming and the command timeout.
    void tick(uint64_t now_ns) { handle(safety_.tick(now_ns)); }

    void kill_switch_read(bool set) override;
    // CommandGate, answered by its CommandAcceptance (the Teensy is made before the Vehicle).
    Result state_error() const override { return acceptance_.state_error(); }
    bool powered_off() const override { return acceptance_.powered_off(); }
    Result accept_command(std::string_view client, const Result& range) override {
        return acceptance_.accept_command(client, range);
    }
    CommandAcceptance& acceptance() { return acceptance_; }
    // Inside a safety sequence being carried out (SafetyActuator::carry_out): the failsafes
    // decide a condition pushed meanwhile once it is done, not halfway through it.
    bool acting() const { return acting_; }

private:
    Result clear();
    void arm_deadline() { deadline_.arm(safety_.next_deadline()); }
    // Every SafetyAction goes through here once; `kill`: it is a kill (SafetyActuator::carry_out).
    void handle(const SafetyAction& a, const Result* kill = nullptr);

    const DaemonConfig& config_;
    SafetyLines& lines_;
    TeensyPort& teensy_;
    VehicleEvents& events_;
    SafetyActuator actuator_;
    SafetyMachine safety_;
    DeadlineTimer deadline_;

    VehicleCondition condition_;
    PilotWatch pilots_;
    CommandAcceptance acceptance_;
    MotorCommands motors_;
    VehicleReadings readings_;
    bool acting_ = false;
};

} // namespace caracara
