// caracarad.toml: parsed into plain structs with defaults and strict validation. An invalid
// file is refused as a whole; every problem is reported as "<key>: <problem>" (with the
// line when known), and unknown keys are errors so a typo cannot silently fall back to a
// default. daemon/caracarad.toml.example documents every key.
//
// The driver-level settings are produced directly as the drivers' own config structs
// (ThrusterConfig, SpiConfig, TeensyLinkConfig), and the thruster set is cross-checked
// with validate_thruster_set(), so a file this parser accepts is one the drivers accept.
#pragma once

#include "core/budget.hpp"
#include "core/enum_names.hpp"
#include "core/failsafe.hpp"
#include "core/mixing.hpp"
#include "core/safety.hpp"
#include "core/link_config.hpp"
#include "core/thruster_config.hpp"

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace caracara {

struct I2cSettings {
    std::string device = "/dev/i2c-1";
    // The bus clock is set by the device tree (dtparam=i2c_arm_baudrate), not by the
    // daemon; the key describes the vehicle (caracara-sim reads it from the same file).
    uint32_t clock_hz = 100000;
    // I2C_TIMEOUT (kernel units of 10 ms): a few times the longest transfer at 100 kHz
    // (a status read, ~1.2 ms), rounded up to the kernel's unit.
    std::optional<uint32_t> timeout_ms = 20;
    std::optional<uint32_t> retries;     // I2C_RETRIES; unset: kernel default
};

struct SpiSettings {
    std::string device = "/dev/spidev0.0";
    SpiConfig spi;              // speed_hz, byte_delay_us (per_byte_delay_us in the file)
    TeensyLinkConfig teensy;    // busy retries/delay, servo and distance sensor counts
    // The vehicle has a Teensy: one absent at start, or never answering, is teensy-link-lost
    // (a kill). false: an absent Teensy is no failsafe until it has answered once.
    bool fitted = true;
    // No valid frame for this long is teensy-link-lost. Unset: ten poll periods (one poll per
    // loop cycle: 200 ms at 50 Hz), at least 200 ms, so a loaded host's late cycle is no kill.
    uint32_t silence_ms = 200;
};

// The name of the error a silence_ms shorter than the link can answer in gets, in its message.
inline constexpr std::string_view kTeensySilenceError = "TeensySilenceTooShort";

struct GpioLineSettings {
    std::string chip = "gpiochip0";
    std::string name;                 // the line's name, or empty when `offset` is used
    std::optional<uint32_t> offset;   // the line's offset on `chip`
    bool active_low = false;
};

struct GpioSettings {
    std::optional<GpioLineSettings> kill_switch;       // input: set = kill
    std::optional<GpioLineSettings> kill_output;       // output: asserted = thrusters de-energized
    std::optional<GpioLineSettings> power_off_output;  // output: asserted = power off
    std::optional<GpioLineSettings> scl;               // bus-clear lines (both or neither)
    std::optional<GpioLineSettings> sda;
};

struct ControlSettings {
    uint32_t loop_rate_hz = 50;           // 0: as fast as the bus allows
    uint32_t status_reads_per_tick = 1;   // thrusters polled for status per tick, round robin
    uint32_t command_timeout_ms = 500;    // silent command stream -> zero output (not a kill)
    uint32_t arming_delay_ms = 3000;      // zero output after a kill is cleared
    BudgetPolicy budget_policy = BudgetPolicy::Scale;
    bool arm_at_start = false;            // false: every start comes up killed (source "start")
    std::string profile = "water";        // the thrust profile selected at start
};

// A named scale factor for every motor value, applied after mixing and before the budget:
// teams test in air at a fraction of the thrust they use in water.
struct ThrustProfile {
    std::string name;
    double factor = 1.0; // 0 < factor <= 1
};

struct RecoverySettings {
    bool enabled = false;  // needs gpio.scl and gpio.sda
    uint32_t attempts = 3;
    uint32_t backoff_ms = 100;  // wait between failed attempts
    // Raspberry Pi: taking GPIO2/3 as GPIO steals them from the I2C controller, and only
    // unbinding and rebinding its platform driver gives them back. Paths and the device id
    // differ per board; an empty driver_id skips the rebind (boards or the simulator that
    // do not need it).
    std::string unbind_path = "/sys/bus/platform/drivers/i2c-bcm2835/unbind";
    std::string bind_path = "/sys/bus/platform/drivers/i2c-bcm2835/bind";
    std::string driver_id;
    uint32_t device_wait_ms = 1000;  // how long to wait for the i2c device node to return
};

// The dive recorder (docs/dive-format.md): one file per dive, from an arming to the next
// kill or power-off, in `directory` (caracarad.service's LogsDirectory=); the oldest dives
// are deleted when the files together pass `max_total_mb`.
struct RecorderSettings {
    bool enabled = true;
    std::string directory = "/var/log/caracara";
    uint32_t max_total_mb = 256;  // about 7 hours of dives at 50 Hz
};

// Real-time scheduling for the daemon's own threads (docs/realtime.md). The loop carries the
// kill switch's edge and the kill output, so it runs above the workers: a kill preempts the
// wire. All below 50, the priority of PREEMPT_RT's threaded interrupts, so the I2C, SPI and
// GPIO interrupt threads the daemon waits on are never starved by the daemon itself.
enum class SchedPolicy { Fifo, RoundRobin };
template <>
struct EnumNames<SchedPolicy> {
    static constexpr std::array<EnumName<SchedPolicy>, 2> table{{
        {SchedPolicy::Fifo, "fifo"},
        {SchedPolicy::RoundRobin, "rr"},
    }};
};

struct RealtimeSettings {
    bool enabled = true;                  // false: every thread at the normal policy
    SchedPolicy policy = SchedPolicy::Fifo;
    uint32_t loop_priority = 40;          // the event loop: kill switch edge, kill output, ticks
    uint32_t bus_priority = 38;           // the bus worker: the I2C transfers
    uint32_t teensy_priority = 36;        // the Teensy worker: the SPI frames
    bool lock_memory = true;              // mlockall: no page fault on the hot path
};

// The default vehicle: eight SeaBotix controllers at MT 0x52, 0x56, 0x58, 0x5A, 0x5C,
// 0x5E, 0x60, 0x62 (distinct even addresses, all on the main bus).
// Commissioning at the pool (docs/commissioning.md): how hard and how long one thruster may
// be run by a motor test, the caller's keep-alive.
struct CommissioningSettings {
    // |value| a motor test may order: small by default, a thruster run in the air or by a
    // vehicle held at the side (motor units, -8850..8850).
    int32_t motor_test_limit = 1500;
    // The caller repeats its MotorTest call within this or the thruster stops (ArduSub's 500 ms).
    uint32_t motor_test_keepalive_ms = 500;
    // Direction detection: each thruster pulsed alone at this value for this long, once the
    // vehicle has held still (each angle's mean moved at most settle_mrad between the halves of
    // settle_ms; waited for at most settle_timeout_ms); a change under threshold_mrad along the
    // mixing's rotation is inconclusive.
    int32_t detect_pulse_value = 3000;       // motor units
    uint32_t detect_pulse_ms = 800;
    uint32_t detect_threshold_mrad = 10;     // along the mixing's rotation
    // Still enough to pulse: the angles' drift between the window's halves, the window, the wait.
    uint32_t detect_settle_mrad = 5;
    uint32_t detect_settle_ms = 1000;
    uint32_t detect_settle_timeout_ms = 10000;
};

std::array<ThrusterConfig, kMotorCount> default_thrusters();

struct DaemonConfig {
    I2cSettings i2c;
    SpiSettings spi;
    std::array<ThrusterConfig, kMotorCount> thrusters = default_thrusters();
    MixMatrix mixing = default_mix_matrix();
    ControlSettings control;
    GpioSettings gpio;
    RecoverySettings recovery;
    RecorderSettings recorder;
    FailsafeSettings failsafe;
    RealtimeSettings realtime;
    std::vector<ThrustProfile> profiles{{"water", 1.0}};
    CommissioningSettings commissioning;
};

// The profile called `name`, or nullptr.
const ThrustProfile* find_profile(const DaemonConfig& config, std::string_view name);
// "air, water": the configured profile names, for messages.
std::string profile_names(const DaemonConfig& config);

struct ConfigResult {
    std::optional<DaemonConfig> config;  // set when valid
    std::vector<std::string> errors;     // every problem found, "<key>: <problem>"
    std::string error() const;           // errors joined by newlines; "" when valid
    bool ok() const { return config.has_value(); }
};

// `source` names the text in messages (a file path); empty: messages carry no prefix.
ConfigResult parse_config_string(std::string_view text, std::string_view source = {});
// Reads and parses the file; messages are prefixed with the path.
ConfigResult parse_config_file(const std::string& path);

// The safety machine's timing from [control].
SafetyConfig safety_config(const DaemonConfig& config);

} // namespace caracara
