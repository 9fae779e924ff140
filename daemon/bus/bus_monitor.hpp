// The I2C bus's health as its transfers tell it: the bus's telemetry (state, counts, the last
// error, the recovery figures) and lockup detection, which tells a whole bus that stopped
// answering from one thruster that did and tells the listener (BusRecovery). While the bus is
// closed for recovery on purpose, its failures say nothing.
#pragma once

#include "core/enum_names.hpp"
#include "core/lockup_detector.hpp"
#include "daemon/interfaces/vehicle_events.hpp"
#include "drivers/platform/io_error.hpp"

#include <cstdint>
#include <string>
#include <string_view>

namespace caracara {

enum class BusState { Ok, Recovering, Lost };
template <>
struct EnumNames<BusState> {
    static constexpr std::array<EnumName<BusState>, 3> table{{
        {BusState::Ok, "ok"},
        {BusState::Recovering, "recovering"},
        {BusState::Lost, "lost"},
    }};
};
inline std::string_view bus_state_name(BusState v) { return name_of(v); }

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

class BusMonitor {
public:
    class Listener {
    public:
        virtual ~Listener() = default;
        virtual void bus_locked_up(const std::string& reason) = 0;
        // A transfer got through on a bus that was lost.
        virtual void bus_back() = 0;
    };

    BusMonitor(std::string device, VehicleEvents& events);
    void set_listener(Listener* l) { listener_ = l; }

    // A finished transfer's outcome (on the loop thread).
    void note(IoError e);
    // While recovering, the adapter is closed on purpose: no bus work, and failures say nothing.
    bool recovering() const { return recovering_; }
    void set_recovering(bool r);
    // The bus itself works: a failed transfer now is the thruster's, not the bus's.
    bool healthy() const { return !recovering_ && tm_.state == BusState::Ok; }

    BusTelemetry& telemetry() { return tm_; }
    const BusTelemetry& telemetry() const { return tm_; }
    const std::string& device() const { return device_; }

private:
    VehicleEvents& events_;
    std::string device_;
    LockupDetector lockup_;
    BusTelemetry tm_;
    bool recovering_ = false;
    Listener* listener_ = nullptr;
};

} // namespace caracara
