// The simulated Teensy I/O microcontroller: an SPI slave speaking the seed protocol
// ("Raspberry Pi - Teensy SPI protocol" documentation) plus this vehicle's extension (0x09 Set LEDs).
//
// It works byte by byte, as the Teensy's SPI interrupt does: a frame is
// [command][data 0-4][answer 0-4][ack]; the command byte alone tells the slave how many data
// and answer bytes follow. While byte k is shifted in, the slave shifts out what it loaded after
// byte k-1: zeros during the command and data slots, the answer once all data has arrived, and
// the ack (= command id) last. Frames may come as one transfer or as one transfer per byte;
// releasing chip select (end_message) always returns the slave to "expect a command".
//
// Decisions the seed leaves open (documented in the protocol docs as well):
// - Confirm (0x01) has no data byte and one answer byte. The slave answers 0xFF there when the
//   running task has finished, else 0. The host acknowledges a finished task by transmitting a
//   non-zero byte (uint8 "positive") on MOSI during that same answer slot; the slave reads it
//   there, and the task becomes idle when the frame completes.
// - Invalid arguments (servo id or sensor id out of range, servo angle > 180, axis > 2,
//   non-finite turn angle): the frame is not executed, its answer slots are zero and the ack
//   slot carries 0x00 ("not acknowledged"), which the host sees as an error. Counted.
// - Unknown command: the slave cannot know the frame length, so it shifts out 0x00 until chip
//   select is released (the host sees ack 0x00, a link error). Logged as Unknown.
// - A frame takes effect only once its ack slot has been shifted out: a frame cut short by
//   chip select is discarded, so the host's resend never doubles a relative Turn.
// - Turn / Turn to: the Teensy turns by its drive wheels, which the attitude model does not
//   know about; the reported heading is the body's yaw plus an internal offset that a running
//   turn task moves at the configured rate. The remaining angle is fixed when the task starts
//   (Turn to takes the shortest way); body motion during the task is not compensated.
// - Stop ends a running turn where it is and marks it finished, so a host polling Confirm
//   is not left waiting for a turn that will never complete.
//
// Fault injection (its TeensyFaults), decided when the command byte arrives (frames of known commands only;
// the first matching rule wins):
//   no answer  (N frames): MISO all 0x00; models a Teensy that is not listening (resetting,
//                          hung interrupt), so the frame is not executed;
//   garbage ack (N frames): the ack slot carries command ^ 0xA5 (never the command, 0x00 or
//                          0xFF for a valid id); models corruption on MISO only, so the frame
//                          IS executed and its answer bytes are real;
//   busy        (N frames, then with probability p from a seeded RNG): answer slots 0x00,
//                          ack 0xFF, not executed (the host resends).
//
// Not thread-safe: the simulator drives all models from one thread.
#pragma once

#include "core/enum_names.hpp"
#include "sim/spi_slave.hpp"
#include "sim/stepped.hpp"
#include "sim/teensy_config.hpp"
#include "sim/teensy_faults.hpp"
#include "sim/teensy_frame_log.hpp"
#include "sim/teensy_frame_record.hpp"
#include "sim/teensy_wheels.hpp"
#include "sim/vehicle_body.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <random>
#include <string_view>
#include <vector>

namespace caracara::sim {

// The firmware's commands, by their id on the wire (named in the frame log: teensy_command_name).
enum class TeensyCommand : uint8_t {
    Confirm = 0x01,
    SetSpeed,
    Turn,
    TurnTo,
    Stop,
    Servo,
    GetDistance,
    GetOrientation,
    SetLeds,
};

namespace teensy {
inline constexpr uint8_t kConfirm = static_cast<uint8_t>(TeensyCommand::Confirm);
inline constexpr uint8_t kSetSpeed = static_cast<uint8_t>(TeensyCommand::SetSpeed);
inline constexpr uint8_t kTurn = static_cast<uint8_t>(TeensyCommand::Turn);
inline constexpr uint8_t kTurnTo = static_cast<uint8_t>(TeensyCommand::TurnTo);
inline constexpr uint8_t kStop = static_cast<uint8_t>(TeensyCommand::Stop);
inline constexpr uint8_t kServo = static_cast<uint8_t>(TeensyCommand::Servo);
inline constexpr uint8_t kGetDistance = static_cast<uint8_t>(TeensyCommand::GetDistance);
inline constexpr uint8_t kGetOrientation = static_cast<uint8_t>(TeensyCommand::GetOrientation);
inline constexpr uint8_t kSetLeds = static_cast<uint8_t>(TeensyCommand::SetLeds);

inline constexpr uint8_t kAckBusy = 0xFF;       // in the ack slot
inline constexpr uint8_t kAckNone = 0x00;       // invalid argument / unknown command / not listening
inline constexpr uint8_t kTaskFinished = 0xFF;  // in Confirm's answer slot
inline constexpr uint8_t kGarbageXor = 0xA5;
inline constexpr std::size_t kMaxServoDegrees = 180;
} // namespace teensy

enum class TeensyTaskState : uint8_t { Idle, Running, FinishedAwaitingAck };

// The command's name, "Unknown" for an id the firmware does not know.
std::string_view teensy_command_name(uint8_t command);
} // namespace caracara::sim
namespace caracara {
template <>
struct EnumNames<sim::TeensyCommand> {
    static constexpr std::array<EnumName<sim::TeensyCommand>, 9> table{{
        {sim::TeensyCommand::Confirm, "Confirm"},
        {sim::TeensyCommand::SetSpeed, "SetSpeed"},
        {sim::TeensyCommand::Turn, "Turn"},
        {sim::TeensyCommand::TurnTo, "TurnTo"},
        {sim::TeensyCommand::Stop, "Stop"},
        {sim::TeensyCommand::Servo, "Servo"},
        {sim::TeensyCommand::GetDistance, "GetDistance"},
        {sim::TeensyCommand::GetOrientation, "GetOrientation"},
        {sim::TeensyCommand::SetLeds, "SetLeds"},
    }};
};
template <>
struct EnumNames<sim::TeensyTaskState> {
    static constexpr std::array<EnumName<sim::TeensyTaskState>, 3> table{{
        {sim::TeensyTaskState::Idle, "idle"},
        {sim::TeensyTaskState::Running, "running"},
        {sim::TeensyTaskState::FinishedAwaitingAck, "finished-awaiting-ack"},
    }};
};
} // namespace caracara
namespace caracara::sim {

class TeensyModel : public SpiSlave, public Stepped {
public:
    using AttitudeSource = std::function<BodyAttitude()>;

    TeensyModel(TeensyConfig cfg, AttitudeSource attitude);
    // The body must outlive the model.
    TeensyModel(TeensyConfig cfg, const VehicleBody& body);

    void transfer(std::span<const uint8_t> tx, std::span<uint8_t> rx, const SpiTransferParams& p,
                  uint64_t now_ns) override;
    void end_message(uint64_t now_ns) override;
    void step(double dt_s, uint64_t now_ns) override;

    // --- fault injection ---
    TeensyFaults& faults() { return faults_; }
    const TeensyFaults& faults() const { return faults_; }

    // --- settable sensor values ---
    bool set_distance_mm(std::size_t sensor, uint16_t mm);

    // --- observation ---
    const TeensyFrameLog& frames() const { return frames_; }

    TeensyWheels wheels() const { return wheels_; }
    uint8_t stop_duty() const { return stop_duty_; }
    float last_turn_rad() const { return last_turn_; }       // argument of the last Turn
    float last_turn_to_rad() const { return last_turn_to_; } // argument of the last Turn to
    double turn_target_heading() const { return target_heading_; }
    double turn_remaining_rad() const { return remaining_; }
    TeensyTaskState task_state() const { return task_; }
    uint64_t acknowledgements() const { return acks_; }
    const std::vector<uint8_t>& servo_degrees() const { return servos_; }
    const std::vector<uint16_t>& distances_mm() const { return distances_; }
    std::array<uint8_t, 3> leds() const { return leds_; }
    // The sensor's reading without noise: body attitude with the heading offset and the drift
    // applied to yaw.
    BodyAttitude orientation() const;
    // What Get orientation answers: orientation() plus the configured noise (a new draw each call).
    BodyAttitude measured_orientation();
    double yaw_drift_rad() const { return drift_; }
    // caracara-sim --replay: Get orientation answers this instead (nullopt: the body model).
    void replay_orientation(const std::optional<BodyAttitude>& a) { replayed_ = a; }
    double heading_offset() const { return heading_offset_; }
    const TeensyConfig& config() const { return cfg_; }

private:
    using Plan = TeensyFramePlan;

    struct Frame {
        bool active = false;
        bool known = false;
        uint8_t cmd = 0;
        std::size_t data_len = 0;
        std::size_t answer_len = 0;
        std::size_t pos = 0; // slot index of the next byte
        Plan plan = Plan::Normal;
        bool invalid = false;
        std::array<uint8_t, 4> data{};
        std::array<uint8_t, 4> answer{};
        uint8_t host_answer0 = 0; // what the host sent in the first answer slot
        uint64_t start_ns = 0;
        std::vector<uint8_t> mosi;
        std::vector<uint8_t> miso;
    };

    uint8_t on_byte(uint8_t in, uint64_t now_ns);
    void begin_frame(uint8_t cmd, uint64_t now_ns);
    void prepare_answer();
    uint8_t slot_output() const;
    uint8_t ack_byte() const;
    void finish_frame(uint64_t now_ns);
    void execute();
    void log_frame(TeensyFrameOutcome o, uint64_t now_ns);
    double heading() const;

    TeensyConfig cfg_;
    AttitudeSource attitude_;
    Frame f_;
    TeensyFaults faults_;
    TeensyFrameLog frames_;

    TeensyWheels wheels_{};
    uint8_t stop_duty_ = 0;
    float last_turn_ = 0.0f;
    float last_turn_to_ = 0.0f;
    double target_heading_ = 0.0;
    double remaining_ = 0.0;
    double heading_offset_ = 0.0;
    TeensyTaskState task_ = TeensyTaskState::Idle;
    uint64_t acks_ = 0;
    std::vector<uint8_t> servos_;
    std::vector<uint16_t> distances_;
    std::optional<BodyAttitude> replayed_;
    std::array<uint8_t, 3> leds_{};
    double drift_ = 0.0; // rad, accumulated yaw drift
    std::mt19937_64 noise_rng_;
    std::normal_distribution<double> noise_;
};

} // namespace caracara::sim
