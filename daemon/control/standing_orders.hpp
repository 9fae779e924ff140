// The orders standing now and the order schedule of the control loop's cycles: what each
// thruster is to be ordered (Vehicle's last demand_changed) and which transfers are due. The
// one owner of both; BusWorkDispatch asks it for the next transfer and hands it to the bus.
#pragma once

#include "core/motor_demand.hpp"
#include "core/order_schedule.hpp"
#include "daemon/bus/thruster_bus.hpp"
#include "daemon/interfaces/demand_listener.hpp"

#include <cstdint>

namespace caracara {

class StandingOrders final {
public:
    explicit StandingOrders(ThrusterBus& bus) : bus_(bus), schedule_(bus.size()) {}

    void start_cycle(uint32_t status_reads, bool teensy) { schedule_.start_cycle(status_reads, teensy); }
    bool order_due() const { return schedule_.any_order_due(); }
    bool nothing_due() const { return schedule_.empty(); }
    // The next item of the schedule: an order or a status read handed to the bus worker here;
    // the Teensy's slot or nothing left to the caller.
    OrderSchedule::Kind hand_over_next();

    // Marks due the orders that changed or are not on the wire; true if any is.
    bool demand_changed(const MotorValues& orders);
    void zero_all(ZeroOrder where);
    void resend();

private:
    ThrusterBus& bus_;
    OrderSchedule schedule_;
    // Kept: each thruster's order while it waits for a slot, re-sent each tick and after a recovery.
    MotorValues orders_{};
};

} // namespace caracara
