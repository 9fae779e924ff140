#include "daemon/control/standing_orders.hpp"

namespace caracara {

OrderSchedule::Kind StandingOrders::hand_over_next() {
    // While the bus is closed for recovery nothing is due on it: the recovery re-sends every
    // order when it is back (resend), and the next cycle marks the rest again.
    const bool bus_usable = !bus_.monitor().recovering();
    if (!bus_usable)
        schedule_.drop_bus_work();
    const OrderSchedule::Item item = schedule_.next(bus_usable);
    if (item.kind == OrderSchedule::Kind::Order)
        bus_.send_order(item.index, orders_[item.index]);
    else if (item.kind == OrderSchedule::Kind::Status)
        bus_.read_status(item.index);
    return item.kind;
}

bool StandingOrders::demand_changed(const MotorValues& orders) {
    bool any_due = false;
    for (size_t i = 0; i < bus_.size() && i < kMotorCount; ++i)
        if (orders[i] != orders_[i] || bus_.ordered_value(i) != orders[i]) {
            schedule_.mark_order(i);
            any_due = true;
        }
    orders_ = orders;
    return any_due;
}

void StandingOrders::zero_all(ZeroOrder where) {
    // Behind: a command the client had sent reaches the wire before its zeros, so a one-shot
    // `busctl call` moves the thrusters for a moment, whether or not its disconnect arrives
    // before the loop sent the orders.
    if (where == ZeroOrder::Behind)
        for (size_t i = 0; !bus_.monitor().recovering() && schedule_.pop_order(i);)
            bus_.send_order(i, orders_[i]);
    orders_.fill(0);
    schedule_.drop_orders();
    bus_.zero_all(where);
    bus_.worker().wake_when_done();
}

void StandingOrders::resend() {
    for (size_t i = 0; i < bus_.size() && i < kMotorCount; ++i)
        bus_.send_order(i, orders_[i]);
}

} // namespace caracara
