#include "core/order_schedule.hpp"

#include <bit>

namespace caracara {

void OrderSchedule::start_cycle(uint32_t status_reads, bool teensy) {
    if (!any_order_due())
        order_due_ = all_;
    status_due_ = status_reads;
    teensy_due_ = teensy;
}

void OrderSchedule::drop_bus_work() {
    drop_orders();
    status_due_ = 0;
}

bool OrderSchedule::pop_order(std::size_t& i) {
    if (order_due_ == 0)
        return false;
    i = static_cast<std::size_t>(std::countr_zero(order_due_)); // the lowest thruster first
    order_due_ &= order_due_ - 1;
    return true;
}

OrderSchedule::Item OrderSchedule::next(bool bus_usable) {
    if (bus_usable) {
        if (std::size_t i = 0; pop_order(i))
            return {Kind::Order, i};
        if (status_due_ > 0 && thrusters_ > 0) {
            --status_due_;
            const std::size_t i = status_next_;
            status_next_ = (status_next_ + 1) % thrusters_;
            return {Kind::Status, i};
        }
    }
    if (teensy_due_) {
        teensy_due_ = false;
        return {Kind::Teensy, 0};
    }
    return {};
}

} // namespace caracara
