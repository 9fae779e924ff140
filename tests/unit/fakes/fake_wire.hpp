// What reached the "wire" of the in-process fakes of the device seam (FakeDeviceIo, FakeGpio),
// in the order it got there: every thruster order with its motor value, every status read, and
// every write of the kill and power-off outputs, every SCL pulse and STOP of a bus clear. Tests
// judge the daemon's objects from it, as
// the e2e tests judge the whole daemon from the simulator's wire log. Thread-safe: the bus
// worker writes from its own thread.
#pragma once

#include <cstddef>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <vector>

namespace caracara::test {

struct WireEvent {
    enum class Kind { Order, StatusRead, KillOutput, PowerOff, SclPulse, Stop };
    Kind kind = Kind::Order;
    std::size_t thruster = 0; // Order, StatusRead
    int32_t value = 0;        // Order: the motor value the speed byte means; outputs: 0/1
    uint8_t speed = 0;        // Order: the SeaBotix speed byte

    bool is_order(std::size_t i, int32_t v) const { return kind == Kind::Order && thruster == i && value == v; }
};

class FakeWire {
public:
    void add(const WireEvent& e) {
        std::lock_guard lk(mu_);
        events_.push_back(e);
    }
    std::vector<WireEvent> events() const {
        std::lock_guard lk(mu_);
        return events_;
    }
    void clear() {
        std::lock_guard lk(mu_);
        events_.clear();
    }
    // Thruster i answers every transfer with -err from now on (0: answers again).
    void fail(std::size_t i, int err) {
        std::lock_guard lk(mu_);
        at(i).failing = err;
    }
    int failure(std::size_t i) const {
        std::lock_guard lk(mu_);
        return of(i).failing;
    }
    // Thruster i's status replies carry these FAULT bits (SeaBotix IDS 8.4.2 word 2; 0: none).
    void set_faults(std::size_t i, uint8_t bits) {
        std::lock_guard lk(mu_);
        at(i).faults = bits;
    }
    uint8_t faults(std::size_t i) const {
        std::lock_guard lk(mu_);
        return of(i).faults;
    }
    // A slave holds SDA low until it has seen `pulses` SCL clock pulses (a bus clear's), or SCL
    // low for good: meanwhile every transfer times out (ETIMEDOUT), as on a locked bus.
    void hold_sda(unsigned pulses) {
        std::lock_guard lk(mu_);
        sda_pulses_ = pulses;
    }
    void hold_scl(bool held) {
        std::lock_guard lk(mu_);
        scl_held_ = held;
    }
    bool locked() const {
        std::lock_guard lk(mu_);
        return sda_pulses_ > 0 || scl_held_;
    }
    bool scl_low() const {
        std::lock_guard lk(mu_);
        return scl_held_;
    }
    bool sda_low() const {
        std::lock_guard lk(mu_);
        return sda_pulses_ > 0;
    }
    // A clock pulse on SCL (the GPIO line let go after being driven low): recorded, and one
    // pulse fewer for the slave that holds SDA.
    void scl_pulse() {
        std::lock_guard lk(mu_);
        events_.push_back({WireEvent::Kind::SclPulse, 0, 0, 0});
        if (sda_pulses_ > 0 && !scl_held_)
            --sda_pulses_;
    }
    // While held, a transfer that reaches the wire waits there (a thruster holding the bus):
    // what the daemon hands over meanwhile queues behind it.
    void hold() {
        std::lock_guard lk(mu_);
        held_ = true;
    }
    void release() {
        {
            std::lock_guard lk(mu_);
            held_ = false;
        }
        released_.notify_all();
    }
    // Blocks while held (called by the transfer); true when it had to wait.
    bool wait_released() {
        std::unique_lock lk(mu_);
        const bool waited = held_;
        waiting_ += waited;
        released_.wait(lk, [this] { return !held_; });
        waiting_ -= waited;
        return waited;
    }
    // A transfer is waiting on the wire.
    bool transfer_waiting() const {
        std::lock_guard lk(mu_);
        return waiting_ > 0;
    }

private:
    // What a test made of one thruster (under mu_).
    struct Thruster {
        int failing = 0;
        uint8_t faults = 0;
    };
    Thruster& at(std::size_t i) {
        if (thrusters_.size() <= i)
            thrusters_.resize(i + 1);
        return thrusters_[i];
    }
    Thruster of(std::size_t i) const { return i < thrusters_.size() ? thrusters_[i] : Thruster{}; }

    mutable std::mutex mu_;
    std::vector<WireEvent> events_;
    std::vector<Thruster> thrusters_;
    unsigned sda_pulses_ = 0;
    bool scl_held_ = false;
    std::condition_variable released_;
    bool held_ = false;
    int waiting_ = 0;
};

} // namespace caracara::test
