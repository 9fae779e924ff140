// Carries the I2C transfers on its own thread (WorkerThread), so that the loop never waits on
// the bus: a hung thruster holds a transfer up to the adapter's timeout, and a Kill, a kill
// switch edge, D-Bus and the watchdog must not queue behind it. Each job (an order or a status
// read) stays in its BusJobQueue's order up to the moment its transfer starts. Only the thread
// touches the drivers, the mux and the adapter while a job is out; the loop reads each driver
// through the copy made after its last job.
#pragma once

#include "daemon/bus/bus_controls.hpp"
#include "daemon/bus/bus_job_queue.hpp"
#include "daemon/bus/bus_transfer.hpp"
#include "daemon/loop/worker_thread.hpp"
#include "drivers/devices/bus_gate.hpp"
#include "drivers/devices/thruster_driver.hpp"
#include "drivers/platform/event_loop.hpp"

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

namespace caracara {

class BusWorker final : public BusControls, private WorkerThread::Jobs {
public:
    using DoneFn = std::function<void(const BusJobDone&)>;

    explicit BusWorker(std::vector<std::unique_ptr<ThrusterDriver>>& drivers);
    ~BusWorker() { stop(); }
    BusWorker(const BusWorker&) = delete;
    BusWorker& operator=(const BusWorker&) = delete;

    // Starts the thread; `done` runs on the loop thread for each finished job, at `priority`.
    std::string start(sd_event* event, int64_t priority, DoneFn done);
    // Joins the thread once the job on the wire is over; queued jobs are dropped.
    void stop();
    bool running() const { return thread_.running(); }

    // An order goes before the queued status reads and, with `replace`, takes the place of one
    // still queued for the same thruster; a status read goes last.
    void submit(const BusJob& job, bool replace = true);
    // The thread is woken once for the jobs submitted between these two (a dispatch of the
    // cycle's work), not at each: when the device answers at once, a wake-up per job costs
    // more than the job. submit_first() always wakes it at once.
    void hold_wakeups() override { holding_wakeups_ = true; }
    void release_wakeups() override;
    // `jobs` go before everything queued, which is dropped (a kill's zero orders).
    void submit_first(std::span<const BusJob> jobs);
    // Drops what is queued but not yet on the wire (the bus is closed for recovery).
    void drop_queued();
    // A kill's fence and the emergency stop's gate: see BusTransfer.
    void hold_orders() override { transfer_.hold_orders(); }
    void set_gate(BusGate* gate) override { transfer_.set_gate(gate); }
    void set_prober(BusProber* prober) { transfer_.set_prober(prober); } // runs the Probe jobs; set while idle
    // Nothing queued, on the wire, or finished but not yet handed to `done`.
    bool idle() const override { return outstanding_ == 0; }
    // At once (the default): the loop is woken as soon as a batch is over. Otherwise it takes the
    // results itself (collect(), at its next tick: a cycle's routine transfers need no wake-up
    // of their own), and only a failed transfer or a long batch wakes it.
    void set_wake_at_once(bool at_once);
    // At once for the jobs handed over so far (call after the last of them): the loop is woken
    // once they are done (a command's orders: its properties show what is on the wire).
    void wake_when_done() override;
    void collect() override { deliver(); }
    // Blocks until idle, handing the finished jobs to `done`: start-up and shutdown only,
    // where the zero orders must be on the wire before the daemon goes on.
    void wait_idle() override;
    // Thruster i as of its last finished job.
    const ThrusterDriver& view(std::size_t i) const { return views_[i]; }

private:
    bool has_job() const override { return !queue_.empty(); }
    bool run_job(std::unique_lock<std::mutex>& lk) override;
    void deliver() override;

    std::vector<std::unique_ptr<ThrusterDriver>>& drivers_;
    std::vector<ThrusterDriver> views_;     // loop thread
    std::vector<ThrusterDriver> published_; // under the lock: the thread's copy after each job
    std::size_t outstanding_ = 0;           // loop thread
    bool holding_wakeups_ = false;          // loop thread
    bool wakeup_owed_ = false;              // loop thread: a job was submitted while holding
    BusTransfer transfer_;

    std::condition_variable finished_; // wait_idle: a job finished
    BusJobQueue queue_;                // under the lock
    std::vector<BusJobDone> done_;     // under the lock
    std::vector<BusJobDone> delivering_; // loop thread; reused
    bool busy_ = false;                // under the lock: a job is on the wire
    bool wake_at_once_ = true;                // under the lock
    bool owed_ = false;                // under the lock: the loop must hear of this batch (a failure)
    DoneFn on_done_;
    WorkerThread thread_{*this}; // last: joined before the rest goes
};

} // namespace caracara
