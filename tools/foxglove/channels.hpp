// The Foxglove channels of the vehicle (docs/foxglove.md): one catalogue of topics, schema
// names and JSON Schemas, and one function per channel that turns a message into its JSON,
// shared by the live bridge (tools/bridge) and the MCAP export of a dive (caracaractl export
// --format mcap), so a recorded dive and a live one look the same in Foxglove.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace caracara::foxglove {

inline constexpr std::size_t kThrusters = 8;

enum class ChannelKind : uint8_t { VehicleState, Motors, Thruster, Teensy, I2cBus, Events, Attitude };

struct ChannelInfo {
    ChannelKind kind;
    unsigned index = 0;          // the thruster number for ChannelKind::Thruster
    std::string topic;           // "/vehicle/state", "/thruster/3", ...
    std::string schema_name;     // "caracara.VehicleState", "foxglove.Log", ...
    std::string schema;          // JSON Schema (draft 2020-12) as text
};

// Every channel, in a fixed order: its position is the channel id the bridge advertises
// (plus one: ids start at 1) and the MCAP channel id.
const std::vector<ChannelInfo>& channels();
// The position in channels() of a channel.
std::size_t channel_position(ChannelKind kind, unsigned index = 0);

inline constexpr const char* kEncoding = "json";
inline constexpr const char* kSchemaEncoding = "jsonschema";

// --- messages (what a channel carries) ---------------------------------------------------------

// One active failsafe, as the daemon's Failsafes property has it (dbus/org.caracara.Vehicle1.xml).
struct ActiveFailsafe {
    std::string condition;       // "water-detect", "pilot-lost", ...
    std::string action;          // "warn", "exclude", "surface", "kill"
    int64_t thruster = -1;       // -1: not one thruster's
};

struct VehicleState {
    std::string state;           // "arming", "ready", "killed", "powered-off", "fault"
    std::string kill_source;     // "" when not killed
    std::string profile;
    double profile_factor = 1.0;
    int64_t budget_limit = 0;
    bool saturated = false;
    int64_t command_age_ms = -1; // -1: no motion command yet, or not recorded
    std::string controller;      // the commanding client's unique bus name
    std::string controller_name; // who that is in words ("caracaractl (pid 812)"); "" unknown
    std::array<int64_t, 3> leds{}; // red, green, blue (not recorded in a dive: 0)
    std::vector<ActiveFailsafe> failsafes;
    int64_t surfacing_ms = -1;   // how long a surface failsafe's ascent has run; -1 none
    int64_t ascent_left_ms = -1; // the time left of that ascent, as the daemon has it; -1 none (or not recorded)
    int64_t pilot_lost_left_ms = -1; // the time left of the pilot-lost failsafe's countdown; -1 none
    int64_t pilot_lost_ms = -1;  // the configured pilot-lost persistence; -1 not known (not recorded)
    // The motor test running (thruster -1 and value 0 when none; not recorded in a dive) and
    // commissioning.motor_test_limit (0 when not known).
    int64_t motor_test_thruster = -1, motor_test_value = 0, motor_test_limit = 0;
    // In the JSON also "excluded": the thrusters an exclude failsafe holds at zero (from failsafes).
};

struct Motors {
    std::array<int64_t, kThrusters> applied{};
    std::array<int64_t, kThrusters> requested{};
};

struct Thruster {
    unsigned index = 0;
    bool reachable = false;
    int64_t speed = 0;           // the reported SPEED as a motor value (-8850..8850); 0 unknown
    int64_t ordered_value = 0;
    double current = 0;          // A
    double temperature = 0;      // degrees C
    unsigned fault_bits = 0;     // the SeaBotix FAULT bits
    std::vector<std::string> faults;
};

struct Teensy {
    bool online = false;
    double yaw = 0, pitch = 0, roll = 0;   // radians
    std::vector<int64_t> distances;        // mm
    std::vector<int64_t> servos;           // degrees
    std::string task;                      // "idle", "turning"
    uint64_t frames = 0, busy_retries = 0, link_errors = 0;
};

struct I2cBus {
    std::string state;           // "ok", "recovering", "lost"
    uint64_t transactions = 0, errors = 0, recoveries = 0, recovery_failures = 0;
    std::string last_error;
};

// foxglove.Log levels.
enum class LogLevel : uint8_t { Unknown = 0, Debug = 1, Info = 2, Warning = 3, Error = 4, Fatal = 5 };

struct LogEvent {
    uint64_t time_ns = 0;
    LogLevel level = LogLevel::Info;
    std::string name;            // "kill", "fault", "bus", "arming", "failsafe", "profile"
    std::string message;
};

// --- JSON ------------------------------------------------------------------------------------

std::string to_json(const VehicleState& m);
std::string to_json(const Motors& m);
std::string to_json(const Thruster& m);
std::string to_json(const Teensy& m);
std::string to_json(const I2cBus& m);
std::string to_json(const LogEvent& m);
// foxglove.FrameTransform of the vehicle ("caracara", body FLU) in "world" (ENU, north +y) from the
// Teensy's yaw (clockwise), pitch (nose up) and roll (right side down), through core/frames.
std::string attitude_json(uint64_t time_ns, double yaw, double pitch, double roll);

// The SeaBotix fault names of a FAULT byte ("overtemp", "stall", ...).
std::vector<std::string> fault_names(unsigned bits);

} // namespace caracara::foxglove
