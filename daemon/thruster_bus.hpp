// The I2C bus to the thrusters: the adapter, the PCA9544A state, one driver per thruster,
// lockup detection and the bus's telemetry.
// The transfers themselves run on the BusWorker's thread; every outcome comes back to the
// loop thread through note(), which spots a locked bus and tells the listener (BusRecovery).
#pragma once

#include "core/config.hpp"
#include "core/lockup_detector.hpp"
#include "daemon/bus_worker.hpp"
#include "daemon/command_gate.hpp"
#include "daemon/vehicle_events.hpp"
#include "drivers/devices/mux_tracker.hpp"
#include "drivers/devices/thruster_driver.hpp"
#include "drivers/platform/device_io.hpp"
#include "drivers/platform/i2c_dev.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace caracara {

enum class BusState { Ok, Recovering, Lost };
std::string_view bus_state_name(BusState s); // "ok", "recovering", "lost"

struct BusTelemetry {
    BusState state = BusState::Ok;
    uint64_t transactions = 0;
    uint64_t errors = 0;
    std::string last_error;
    uint64_t recoveries = 0;       // completed bus recoveries
    uint64_t recovery_failures = 0;
    uint32_t last_pulses = 0;      // SCL pulses the last bus clear needed
    double last_recovery_ms = 0;   // time from detection to orders re-sent
    std::string last_recovery_error;
};

class ThrusterBus {
public:
    class Listener {
    public:
        virtual ~Listener() = default;
        virtual void bus_locked_up(const std::string& reason) = 0;
    };
    ThrusterBus(DeviceIo& io, const DaemonConfig& config, VehicleEvents& events);

    // The adapter is opened and closed only while the worker is idle (see BusWorker).
    int open() { return i2c_.open(); } // 0 or -errno
    void close() { i2c_.close(); }
    // Starts the worker thread; `done` runs on the loop thread after each finished job (the
    // loop hands over the next one).
    std::string start(sd_event* event, int64_t priority, std::function<void(const BusJob&)> done);
    void stop() { worker_.stop(); }
    void set_listener(Listener* l) { listener_ = l; }

    // Each hands one transfer to the worker; its outcome arrives later through note().
    void send_order(std::size_t i, int32_t value);
    void read_status(std::size_t i);
    // Zero to every thruster, back to back: nothing may come between a kill and its zeros.
    void zero_all(ZeroOrder where = ZeroOrder::First);
    // Before a kill's kill output: no non-zero order handed over earlier goes out after it.
    void hold_orders() { worker_.hold_orders(); }
    // A thruster that fails this many transfers in a row (NACK, timeout, bus error; a garbled
    // reply still reached it) is unreachable. A SeaBotix controller keeps its last order for as
    // long as it has power, so the vehicle is killed (source "device") and stays killed until
    // every thruster answers again. Three: more than a lockup of the whole bus takes to be told
    // from one thruster (LockupDetector), so a bus recovery comes first.
    static constexpr uint32_t kUnreachableAfter = 3;
    // Told (device_lost) when a thruster becomes unreachable; at once if one already is.
    void set_gate(CommandGate* gate);
    std::optional<std::size_t> first_unreachable() const;
    // The emergency stop's gate: see BusWorker::set_gate.
    void set_crash_gate(BusGate* gate) { worker_.set_gate(gate); }
    // Blocks until the worker is idle: at start-up and shutdown, where the zeros must be on the
    // wire before the daemon goes on.
    void wait_idle() { worker_.wait_idle(); }
    // No transfer queued or on the wire.
    bool idle() const { return worker_.idle(); }
    // Runs `fn` once the transfers handed over so far are done (at once when idle).
    void when_idle(std::function<void()> fn);

    // While recovering, the adapter is closed on purpose: no bus work, and failures say nothing.
    bool recovering() const { return recovering_; }
    void set_recovering(bool r);
    MuxTracker& mux() { return mux_; }
    bool any_online() const;

    std::size_t size() const { return thrusters_.size(); }
    // Thruster i as of its last finished transfer.
    const ThrusterDriver& thruster(std::size_t i) const { return worker_.view(i); }
    int32_t ordered_value(std::size_t i) const { return ordered_[i]; }
    // The fault bits last reported for thruster i (logged once per change).
    FaultSet faults(std::size_t i) const { return faults_[i]; }
    BusTelemetry& telemetry() { return tm_; }
    const BusTelemetry& telemetry() const { return tm_; }
    const std::string& device() const { return device_; }

private:
    void done(const BusJobDone& d);
    void note(IoError e);
    void report_faults(std::size_t i);
    void track_reach(std::size_t i, IoError e);
    std::string unreachable_reason(std::size_t i) const;

    VehicleEvents& events_;
    std::string device_;
    I2cDev i2c_;
    MuxTracker mux_;
    std::vector<std::unique_ptr<ThrusterDriver>> thrusters_;
    BusWorker worker_;
    std::vector<int32_t> ordered_;
    std::vector<FaultSet> faults_;
    LockupDetector lockup_;
    BusTelemetry tm_;
    bool recovering_ = false;
    Listener* listener_ = nullptr;
    CommandGate* gate_ = nullptr;
    std::vector<uint32_t> failed_in_row_;
    std::vector<bool> unreachable_;
    std::function<void(const BusJob&)> on_done_;
    std::vector<std::function<void()>> when_idle_;
};

} // namespace caracara
