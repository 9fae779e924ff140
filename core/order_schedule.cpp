#include "core/order_schedule.hpp"

#include <algorithm>

namespace caracara {

void OrderSchedule::start_cycle(uint32_t status_reads, bool teensy) {
    if (!any_order_due())
        std::fill(order_due_.begin(), order_due_.end(), true);
    status_due_ = status_reads;
    teensy_due_ = teensy;
}

bool OrderSchedule::any_order_due() const {
    return std::any_of(order_due_.begin(), order_due_.end(), [](bool d) { return d; });
}

void OrderSchedule::drop_orders() { std::fill(order_due_.begin(), order_due_.end(), false); }

void OrderSchedule::drop_bus_work() {
    drop_orders();
    status_due_ = 0;
}

bool OrderSchedule::pop_order(std::size_t& i) {
    for (i = 0; i < order_due_.size(); ++i) {
        if (order_due_[i]) {
            order_due_[i] = false;
            return true;
        }
    }
    return false;
}

OrderSchedule::Item OrderSchedule::next(bool bus_usable) {
    if (bus_usable) {
        if (std::size_t i = 0; pop_order(i))
            return {Kind::Order, i};
        if (status_due_ > 0 && !order_due_.empty()) {
            --status_due_;
            const std::size_t i = status_next_;
            status_next_ = (status_next_ + 1) % order_due_.size();
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
