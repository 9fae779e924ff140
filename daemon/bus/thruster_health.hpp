// Each thruster's health as its transfers tell it: whether it still answers, and the fault bits
// it last reported (logged once per change). A thruster that stops answering is pushed to the
// failsafes as thruster-unreachable (they kill), and its end once every thruster answers.
#pragma once

#include "daemon/interfaces/failsafe_gate.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "drivers/devices/thruster_driver.hpp"
#include "drivers/platform/io_error.hpp"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace caracara {

class ThrusterHealth {
public:
    // A thruster that fails this many transfers in a row (NACK, timeout, bus error; a garbled
    // reply still reached it) is unreachable. A SeaBotix controller keeps its last order for as
    // long as it has power, so the vehicle is killed (source "device") and stays killed until
    // every thruster answers again. Three: more than a lockup of the whole bus takes to be told
    // from one thruster (LockupDetector), so a bus recovery comes first.
    static constexpr uint32_t kUnreachableAfter = 3;

    ThrusterHealth(std::size_t thrusters, VehicleEvents& events);

    // Where thruster-unreachable is pushed (null: nowhere, on the way out); told at once if one
    // already is.
    void set_failsafes(FailsafeGate* failsafes);
    // Thruster i's transfer ended with `e`. `bus_healthy`: the bus itself worked (BusMonitor);
    // a closed adapter (recovery) or a lost bus is the bus's failure, not this thruster's.
    void note(std::size_t i, IoError e, bool bus_healthy);
    // Thruster i's status was read: its fault bits as it reports them now.
    void note_status(std::size_t i, const std::optional<ThrusterStatus>& status);

    std::optional<std::size_t> first_unreachable() const;
    // The fault bits last reported for thruster i.
    FaultSet faults(std::size_t i) const { return faults_[i]; }

private:
    std::string unreachable_reason(std::size_t i) const;

    VehicleEvents& events_;
    FailsafeGate* failsafes_ = nullptr;
    std::vector<FaultSet> faults_;
    std::vector<uint32_t> failed_in_row_;
    std::vector<IoError> last_failure_;
    std::vector<bool> unreachable_;
};

} // namespace caracara
