// The I2C bus to the thrusters: the adapter, the PCA9544A state and one driver per thruster,
// with the BusWorker that carries their transfers on its own thread. Every outcome comes back
// to the loop thread (done()), where the bus's health (BusMonitor) and each thruster's
// (ThrusterHealth) take it in, then the loop hears of it.
#pragma once

#include "core/config.hpp"
#include "daemon/bus/bus_controls.hpp"
#include "daemon/bus/bus_monitor.hpp"
#include "daemon/bus/bus_worker.hpp"
#include "daemon/bus/thruster_health.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "drivers/devices/mux_tracker.hpp"
#include "drivers/devices/thruster_driver.hpp"
#include "drivers/platform/device_io.hpp"
#include "drivers/platform/i2c_dev.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace caracara {

class ThrusterBus {
public:
    ThrusterBus(DeviceIo& io, const DaemonConfig& config, VehicleEvents& events);

    // The adapter is opened and closed only while the worker is idle (see BusWorker).
    int open() { return i2c_.open(); } // 0 or -errno
    void close() { i2c_.close(); }
    // Starts the worker thread; `done` runs on the loop thread after each finished job (the
    // loop hands over the next one).
    std::string start(sd_event* event, int64_t priority, std::function<void(const BusJob&)> done);
    void stop() { worker_.stop(); }

    // Each hands one transfer to the worker; its outcome arrives later through done().
    void send_order(std::size_t i, int32_t value);
    void read_status(std::size_t i);
    // One step of a bus scan, run on the worker's thread behind every order (BusProber);
    // `prober` hears of it on the loop thread, at once.
    void submit_probe(BusProber& prober, uint32_t step);
    // Zero to every thruster, back to back: nothing may come between a kill and its zeros.
    void zero_all(ZeroOrder where = ZeroOrder::First);
    // Runs `fn` once the transfers handed over so far are done (at once when idle).
    void when_idle(std::function<void()> fn);
    // At its tick: the loop takes the results of its routine transfers at its tick (collect()) rather
    // than being woken for them; it is woken anyway while something waits for the bus to be
    // idle (when_idle, a recovery) and for a failure (see BusWorker::set_wake_at_once).
    void set_results_at_tick(bool at_tick) {
        results_at_tick_ = at_tick;
        update_wake_at_once();
    }
    // The worker's own controls (wake-ups, a kill's fence, the emergency stop's gate, idle);
    // orders, status reads and probes go through the ThrusterBus, which keeps what was ordered.
    BusControls& worker() { return worker_; }
    const BusControls& worker() const { return worker_; }

    // The adapter closed for a bus recovery (its queued work dropped) and open again; whether
    // it is, is its BusMonitor's (monitor().recovering()).
    void set_recovering(bool r);
    MuxTracker& mux() { return mux_; }
    // The adapter, for the worker's thread only (a probe step).
    I2cDev& i2c() { return i2c_; }
    bool any_online() const;

    std::size_t size() const { return thrusters_.size(); }
    // Thruster i as of its last finished transfer.
    const ThrusterDriver& thruster(std::size_t i) const { return worker_.view(i); }
    // The value last handed to the worker for thruster i.
    int32_t ordered_value(std::size_t i) const { return ordered_[i]; }
    BusMonitor& monitor() { return monitor_; }
    const BusMonitor& monitor() const { return monitor_; }
    ThrusterHealth& health() { return health_; }
    const ThrusterHealth& health() const { return health_; }

private:
    void done(const BusJobDone& d);
    void update_wake_at_once();

    BusMonitor monitor_;
    ThrusterHealth health_;
    I2cDev i2c_;
    MuxTracker mux_;
    std::vector<std::unique_ptr<ThrusterDriver>> thrusters_;
    BusWorker worker_;
    // Kept: the order last handed to the worker (OrderedValue; one a kill's zeros dropped is due again).
    std::vector<int32_t> ordered_;
    std::function<void(const BusJob&)> on_done_;
    std::vector<std::function<void()>> when_idle_;
    bool results_at_tick_ = false;
    BusProber* prober_ = nullptr;
    bool wake_at_once_ = true; // as last told to the worker
};

} // namespace caracara
