// The simulator's wire log: every I2C message, SPI frame, I2C line event (recovery clocking)
// and GPIO line level change with its monotonic timestamp, in a bounded ring so a long run
// cannot eat memory.
#pragma once

#include "core/clock.hpp"

#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace caracara::sim {

// The kinds of entry, by bus (consumers filter on it):
//   "i2c"        one I2C message: addr = 7-bit address, read, data = the bytes after the
//                address byte; result "ack", "nack", "pins-not-i2c", "sda-held-low", "scl-held-low",
//                "timeout" (the slave held the clock past the adapter's timeout)
//   "spi"        one SPI message: addr = chip select (0), data = MOSI, miso = MISO;
//                result "ok", "no-device", "mode-mismatch"
//   "i2c-lines"  SCL/SDA driven as GPIO (bus recovery): result "scl-pulse", "start", "stop"
//   "gpio"       a line's physical level changed (kill switch, kill output, power-off output):
//                addr = the line offset on gpiochip0, data = {new level on the wire, 0 or 1},
//                result "edge"; time_ns = the moment of the change (gpio_model.hpp)
struct WireEntry {
    uint64_t index = 0;        // monotonic, never reused
    uint64_t time_ns = 0;      // CLOCK_MONOTONIC at the end of the message on the wire
    uint64_t transaction = 0;  // messages of one I2C_RDWR share this (0 for line events)
    std::string bus;           // "i2c", "spi", "i2c-lines", "gpio"
    uint16_t addr = 0;         // 7-bit I2C address (SPI: chip select; gpio: line offset)
    bool read = false;
    std::vector<uint8_t> data; // bytes after the address byte (SPI: MOSI bytes; gpio: {level})
    std::vector<uint8_t> miso; // SPI only: what the slave shifted out
    std::string result;        // see above
};

class WireLog {
public:
    explicit WireLog(size_t capacity = 200000) : capacity_(capacity) {}
    uint64_t append(WireEntry e);
    uint64_t new_transaction() { return ++transaction_; }
    // Entries with index >= since, oldest first, at most max_entries of them.
    std::vector<const WireEntry*> since(uint64_t since_index, size_t max_entries = SIZE_MAX) const;
    uint64_t next_index() const { return next_; }
    void clear() { entries_.clear(); }
    size_t size() const { return entries_.size(); }
    size_t capacity() const { return capacity_; }

private:
    size_t capacity_;
    uint64_t next_ = 1;
    uint64_t transaction_ = 0;
    std::deque<WireEntry> entries_;
};

} // namespace caracara::sim
