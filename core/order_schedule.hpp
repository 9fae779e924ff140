// What the bus does next, in the order the daemon promises: changed orders first (a new
// command's burst), then the status reads of this cycle round robin, then the Teensy's slot.
// Pure: the control loop asks next() and carries the item out; time never enters here.
#pragma once

#include <cstddef>
#include <cstdint>

namespace caracara {

class OrderSchedule {
public:
    enum class Kind { None, Order, Status, Teensy };
    struct Item {
        Kind kind = Kind::None;
        std::size_t index = 0; // the thruster, for Order and Status
    };

    // Up to 32 thrusters (the vehicle has eight).
    explicit OrderSchedule(std::size_t thrusters)
        : thrusters_(thrusters), all_(thrusters >= 32 ? ~0u : (1u << thrusters) - 1u) {}

    // A new cycle: every order is refreshed, unless a burst is still going out (those sent are
    // fresh, the rest already due: restarting it would only delay the last ones).
    void start_cycle(uint32_t status_reads, bool teensy);
    void mark_order(std::size_t i) { order_due_ |= 1u << i; }
    bool any_order_due() const { return order_due_ != 0; }
    // Nothing left of the cycle to hand out.
    bool empty() const { return order_due_ == 0 && status_due_ == 0 && !teensy_due_; }
    // The bus is closed (recovery) or the orders were all sent at once (a kill's zeros).
    void drop_orders() { order_due_ = 0; }
    void drop_bus_work();
    // Orders first, then status reads, then the Teensy. While the I2C bus is unusable only the
    // Teensy's slot is handed out; its orders and reads stay as they are.
    Item next(bool bus_usable);
    // Just the next due order (a client that leaves gets its orders out before the zeros).
    bool pop_order(std::size_t& i);

private:
    std::size_t thrusters_;
    uint32_t all_;
    uint32_t order_due_ = 0; // bit i: thruster i's order is due (a bitmask: this runs per transaction)
    uint32_t status_due_ = 0;
    std::size_t status_next_ = 0;
    bool teensy_due_ = false;
};

} // namespace caracara
