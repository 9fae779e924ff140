// The control loop: owns the thruster drivers and the Teensy link, applies the safety state
// machine, the mixing and the budget, and schedules bus work on the sd-event loop.
//
// Bus work is a small set of "due" flags (an order per thruster, status reads, a Teensy poll)
// executed at a lower priority than D-Bus, several transactions per dispatch but checking for
// a waiting message or kill switch edge between them, so a Kill or a new command waits at most
// for the transaction already on the wire. A kill zeroes every thruster synchronously before
// its D-Bus reply; a new command marks its changed orders due at once.
#pragma once

#include "core/budget.hpp"
#include "core/clock.hpp"
#include "core/status.hpp"
#include "core/config.hpp"
#include "platform/device_io.hpp"
#include "platform/gpio_backend.hpp"
#include "platform/i2c_dev.hpp"
#include "core/mixing.hpp"
#include "core/safety.hpp"
#include "daemon/input_probe.hpp"
#include "platform/event_loop.hpp"
#include "platform/spi_dev.hpp"
#include "devices/teensy_link.hpp"
#include "devices/thruster_driver.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace caracara {

// Event-loop priorities. D-Bus, timers and the kill switch run at SD_EVENT_PRIORITY_NORMAL or
// above; the bus work below them; announcements (PropertiesChanged) below the work, so that
// neither an order nor the reply of the call that caused the change waits for one.
inline constexpr int64_t kWorkPriority = SD_EVENT_PRIORITY_NORMAL + 10;
inline constexpr int64_t kAnnouncePriority = kWorkPriority + 1;

// Which vehicle properties changed, for PropertiesChanged.
enum VehicleChange : uint32_t {
    kChangeState = 1u << 0,      // State, KillSource
    kChangeMotors = 1u << 1,     // MotorValues, RequestedValues, BudgetLimit, Saturated
    kChangeLeds = 1u << 2,
    kChangeController = 1u << 3, // Controller
    kChangeBus = 1u << 4,        // the Bus object's State and recovery figures
};

class ControllerObserver {
public:
    virtual ~ControllerObserver() = default;
    virtual void vehicle_changed(uint32_t changes) = 0;
    // Periodic: thruster, Teensy and bus telemetry, command age, cycles.
    virtual void telemetry() = 0;
    // The I2C bus was found locked up / came back after a recovery.
    virtual void bus_lost(const std::string& reason) = 0;
    virtual void bus_restored(uint32_t pulses, double milliseconds) = 0;
};

struct ThrusterTelemetry {
    int32_t ordered_value = 0;
    uint8_t ordered_speed = 0x80;
};

struct TeensyTelemetry {
    bool online = false;
    std::array<double, 3> orientation{}; // yaw, pitch, roll
    std::vector<uint16_t> distances;
    std::vector<uint8_t> servos;
    bool turning = false;
};

struct BusTelemetry {
    std::string state = "ok";     // "ok", "recovering", "lost"
    uint64_t transactions = 0;
    uint64_t errors = 0;
    std::string last_error;
    uint64_t recoveries = 0;       // completed bus recoveries
    uint64_t recovery_failures = 0;
    uint32_t last_pulses = 0;      // SCL pulses the last bus clear needed
    double last_recovery_ms = 0;   // time from detection to orders re-sent
    std::string last_recovery_error;
};

class Controller {
public:
    Controller(sd_event* event, DeviceIo& io, GpioBackend& gpio, DaemonConfig config);
    ~Controller();
    Controller(const Controller&) = delete;
    Controller& operator=(const Controller&) = delete;

    // Opens the devices and the GPIO lines and orders zero to every thruster. Returns "" or a
    // reason the daemon cannot run (the I2C bus or a configured GPIO line cannot be had).
    // A missing Teensy is not fatal.
    std::string start();
    // Orders zero to every thruster (SIGTERM, fatal errors). Safe to call more than once.
    void shutdown();
    void set_observer(ControllerObserver* o) { observer_ = o; }
    void set_input_probe(const InputProbe* p) { input_ = p; }
    // Other holders of the I2C node (the emergency stop's connection) that must let go of it
    // while the recovery unbinds the adapter's driver, and may take it again once it is back.
    void set_node_holders(std::function<void()> release, std::function<void()> reopen) {
        release_node_holders_ = std::move(release);
        reopen_node_holders_ = std::move(reopen);
    }

    Result set_thrust(std::span<const int32_t> values, std::string_view client);
    Result set_motion(const AxisDemand& demand, std::string_view client);
    Result apply_packet(std::span<const int32_t> words, std::string_view client);
    Result kill(KillSource source, std::string_view reason = {});
    Result clear_kill();
    Result power_off(std::string_view confirmation);
    Result set_leds(int red, int green, int blue);
    void client_left(std::string_view unique_name);

    Result teensy_set_speed(int left, int right);
    Result teensy_stop(int duty);
    Result teensy_servo(int id, int degrees);
    Result teensy_distance(int sensor, uint16_t& mm);
    // Starts a Turn (relative) or Turn to (absolute); `done` runs when the Teensy confirms
    // completion, or on failure. Returns an error at once if it cannot start.
    Result teensy_turn(double radians, bool absolute, std::function<void(const Result&)> done);

    // State for the D-Bus layer.
    const DaemonConfig& config() const { return config_; }
    const SafetyMachine& safety() const { return safety_; }
    std::string_view state_name() const;
    std::string_view kill_source_name() const;
    const MotorValues& motor_values() const { return applied_; }
    const MotorValues& requested_values() const { return requested_; }
    int32_t budget_limit() const { return limit_; }
    bool saturated() const { return saturated_; }
    std::array<uint8_t, 3> leds() const { return leds_; }
    int64_t command_age_ms() const;
    const std::string& controller_client() const { return safety_.commanding_client(); }
    uint64_t cycles() const { return cycles_; }
    size_t thruster_count() const { return thrusters_.size(); }
    const ThrusterDriver& thruster(size_t i) const { return *thrusters_[i]; }
    int32_t ordered_value(size_t i) const { return ordered_[i]; }
    const TeensyTelemetry& teensy() const { return teensy_tm_; }
    const TeensyLinkCounters& teensy_counters() const { return teensy_link_.counters(); }
    const BusTelemetry& bus() const { return bus_tm_; }
    // Healthy = the control loop completed a cycle recently (fed to the systemd watchdog).
    bool healthy(uint64_t now_ns) const;

private:
    static int on_tick(sd_event_source*, uint64_t usec, void* userdata);
    static int on_work(sd_event_source*, void* userdata);
    static int on_resume(sd_event_source*, void* userdata);
    bool input_pending() const;
    static int on_turn_step(sd_event_source*, uint64_t usec, void* userdata);
    static int on_kill_switch(sd_event_source*, int fd, uint32_t revents, void* userdata);
    static int on_recovery_timer(sd_event_source*, uint64_t usec, void* userdata);

    std::string open_gpio();
    void poll_kill_switch();
    void update_outputs();
    // Bus lockup: detection from transfer errors, then the recovery sequence (DESIGN.md).
    bool bus_level_error(IoError e) const;
    void start_recovery(const std::string& reason);
    void recovery_attempt();
    void recovery_wait_node();
    void recovery_finish();
    void recovery_failed(const std::string& why);
    void schedule_recovery(uint64_t delay_ns);

    uint64_t now() const;
    void cycle();
    enum class Work { None, Order, Other };
    Work work_one(); // one transaction, orders first
    void schedule_work();
    bool cycle_overrun_ = false;  // a tick came while a cycle was still going
    bool any_order_due() const;
    void refresh_orders();
    void send_order(size_t i);
    bool send_next_due_order(); // false when none is due (or the bus is being recovered)
    void send_due_orders();     // now, back to back
    void zero_now();
    void handle(const SafetyAction& a);
    Result accept_motors(const MotorValues& wanted, bool mix_saturated, std::string_view client);
    Result state_error() const;
    void note_bus_result(IoError e);
    void poll_teensy();
    void stop_teensy_motion();
    void turn_step();
    void finish_turn(const Result& r);
    void publish_telemetry_if_due();
    void notify(uint32_t changes);

    sd_event* event_;
    DeviceIo& io_;
    GpioBackend& gpio_;
    DaemonConfig config_;
    I2cDev i2c_;
    MuxTracker mux_;
    std::vector<std::unique_ptr<ThrusterDriver>> thrusters_;
    SpiDev spi_;
    TeensyLink teensy_link_;
    SafetyMachine safety_;
    ControllerObserver* observer_ = nullptr;
    const InputProbe* input_ = nullptr;
    std::function<void()> release_node_holders_;
    std::function<void()> reopen_node_holders_;

    MotorValues requested_{};
    MotorValues applied_{};
    std::array<int32_t, kMotorCount> ordered_{};
    int32_t limit_ = 0;
    bool saturated_ = false;
    std::array<uint8_t, 3> leds_{};

    // Due work; see the header comment.
    std::array<bool, kMotorCount> order_due_{};
    uint32_t status_due_ = 0;
    size_t status_next_ = 0;
    bool teensy_due_ = false;
    unsigned teensy_poll_index_ = 0;
    bool in_cycle_ = false;

    SourcePtr tick_source_;
    SourcePtr work_source_;
    SourcePtr resume_source_; // below the announcements: the rest of the work, or the next cycle at rate 0
    SourcePtr turn_source_;
    uint64_t cycles_ = 0;
    uint64_t last_cycle_ns_ = 0;
    uint64_t last_telemetry_ns_ = 0;
    bool started_ = false;

    teensy::ConfirmHandshake handshake_;
    std::function<void(const Result&)> turn_done_;

    TeensyTelemetry teensy_tm_;
    BusTelemetry bus_tm_;

    std::unique_ptr<GpioLine> kill_switch_;
    std::unique_ptr<GpioLine> kill_out_;
    std::unique_ptr<GpioLine> power_off_out_;
    SourcePtr kill_switch_source_;

    enum class RecoveryPhase { Idle, WaitingNode, Backoff };
    RecoveryPhase recovery_phase_ = RecoveryPhase::Idle;
    bool recovering_ = false;           // the bus is down: no bus work until it is back
    uint32_t consecutive_bus_errors_ = 0;
    uint32_t consecutive_failures_ = 0;
    uint32_t attempt_ = 0;
    uint64_t recovery_started_ns_ = 0;
    uint64_t node_deadline_ns_ = 0;
    uint32_t last_pulses_ = 0;
    SourcePtr recovery_timer_;
};

} // namespace caracara
