// The bus scan (docs/commissioning.md, "Bus scan"): with the vehicle killed, a status read at
// every address the SeaBotix IDS names and every address the configuration gives a thruster, on
// the trunk and on each channel of each configured PCA9544A, judged against the configuration
// (core/bus_scan_report). Each probe is one step on the bus worker's thread, run only when no
// order or status read is queued, so the routine zeros and a kill's zeros never wait behind it;
// a kill (its zeros drop the waiting step) or the vehicle leaving "killed" ends the scan. The
// mux is left selecting what it selected before the scan.
#pragma once

#include "core/bus_scan_report.hpp"
#include "core/config.hpp"
#include "core/status.hpp"
#include "daemon/bus/bus_prober.hpp"
#include "daemon/bus/thruster_bus.hpp"
#include "daemon/loop/completion.hpp"
#include "daemon/vehicle/vehicle.hpp"
#include "drivers/devices/thruster_probe.hpp"

#include <cstdint>
#include <optional>
#include <vector>

namespace caracara {

class BusScan final : private BusProber {
public:
    BusScan(const DaemonConfig& config, const Vehicle& vehicle, ThrusterBus& bus);

    // Scans; `done` gets Ok with report() filled, or why it was refused or ended. Refused,
    // touching nothing: a vehicle that is not killed (NotKilled, PoweredOff), a bus being
    // recovered (BusLost), a scan already running (Busy).
    void run(Completion done);
    bool running() const { return static_cast<bool>(done_); }
    const BusScanReport& report() const { return report_; }
    // The daemon is stopping: the caller hears so.
    void stop();

private:
    // A step: a probe of one address on one segment, or (the last) putting the mux back.
    struct Step {
        ScanSegment segment;
        uint8_t mt = 0;
        bool restore = false;
        IoError error = IoError::None; // worker's thread, read on the loop after probed()
        ProbeAnswer answer;
    };
    IoError probe(uint32_t job) override; // job: the scan's number << 16 | the step
    void probed(const BusJobDone& done) override;
    void dropped() override;
    void next(uint32_t step);
    void end(Result r);
    IoError select(const ScanSegment& s);

    const DaemonConfig& config_;
    const Vehicle& vehicle_;
    ThrusterBus& bus_;
    std::vector<Step> steps_; // the same for every scan; results written on the worker's thread
    std::optional<MuxRoute> before_; // worker's thread: what the mux selected when the scan began
    uint16_t scan_ = 0; // this scan's number, in each step's job: a late step of an ended scan is ignored
    BusScanReport report_;
    Completion done_;
};

} // namespace caracara
