// The simulated vehicle's GPIO chip: the I2C pins as open-drain lines onto the bus model's
// wired-AND SCL/SDA, the kill switch input, and the kill and power-off outputs.
//
// Wire log: every change of the physical level of the kill switch, kill output and power-off
// lines is an entry {bus "gpio", addr = line offset, data = {new level, 0 or 1, on the wire
// (before any active-low inversion)}, result "edge"}, stamped with the CLOCK_MONOTONIC time of
// the change, before edge watchers are told (the same stamp as their GpioEvent). SCL/SDA are
// logged as I2C line events instead ({bus "i2c-lines", result "scl-pulse", "start", "stop"}).
#pragma once

#include "sim/i2c_bus_model.hpp"
#include "drivers/protocol/sim_protocol.hpp"
#include "sim/wire_log.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace caracara::sim {

using simproto::GpioMode;

struct GpioLineInfo {
    std::string name;
    uint32_t offset;
};

class GpioModel {
public:
    // Offsets follow a Raspberry Pi: GPIO2/3 are I2C1 SDA/SCL.
    static constexpr uint32_t kSda = 2, kScl = 3, kKillSwitch = 17, kPowerOff = 22, kKillOut = 27;
    static constexpr const char* kChip = "gpiochip0";

    GpioModel(I2cBusModel& bus, WireLog& log, bool kill_switch_active_low);

    // Line lookup by chip and name, or offset (>= 0). -ENOENT when there is no such line.
    int find(const std::string& chip, const std::string& name, int offset) const;
    // -EBUSY if the line is already requested, -ENODEV while it is gone; 0 on success.
    int request(int line, GpioMode mode, bool active_low, int initial, uint64_t now_ns);
    int get(int line) const;                          // logical value; -ENODEV while gone
    int set(int line, int logical, uint64_t now_ns);  // -EPERM on an input; -ENODEV while gone
    void release(int line, uint64_t now_ns);
    bool requested(int line) const { return lines_[static_cast<size_t>(line)].requested; }

    // The simulator's side.
    void set_kill_switch(bool engaged, uint64_t now_ns);
    // One line taken away (its driver gone, as a vanished chip is for every line) and brought
    // back: while gone it is released (an output's level drops), requests, reads and writes get
    // -ENODEV, and a handle from before never works again (epoch). Logged as {bus "gpio",
    // addr = offset, result "gone" or "back"}; on_gone tells the edge watchers' server.
    void set_present(int line, bool present, uint64_t now_ns);
    bool present(int line) const { return !gone_[static_cast<size_t>(line)]; }
    uint32_t epoch(int line) const { return epochs_[static_cast<size_t>(line)]; }
    std::function<void(int)> on_gone;
    bool kill_switch_engaged() const { return kill_switch_engaged_; }
    bool kill_switch_active_low() const { return kill_switch_active_low_; } // engaged = low on the wire
    bool level(uint32_t offset) const; // physical level on the wire
    uint64_t stops() const { return stops_; }
    uint64_t scl_pulses() const { return scl_pulses_; }
    uint64_t min_scl_period_ns() const { return min_scl_period_ns_; }
    const std::vector<GpioLineInfo>& lines() const { return info_; }

    // Called with (line index, its value as get() reports it, the time of the change) on every
    // change of a line's physical level, requested or not (edge watchers see the kill switch
    // before it is requested), after the change is in the wire log.
    std::function<void(int, int, uint64_t)> on_change;

private:
    struct Line {
        bool requested = false;
        GpioMode mode = GpioMode::Input;
        bool active_low = false;
        bool drive = true; // physical level this side drives (open drain: true = released)
    };
    bool physical(size_t i) const;
    void update(uint64_t now_ns, const std::vector<bool>& before);
    std::vector<bool> levels() const;

    I2cBusModel& bus_;
    WireLog& log_;
    bool kill_switch_active_low_;
    bool kill_switch_engaged_ = false;
    std::vector<GpioLineInfo> info_;
    std::vector<Line> lines_;
    std::vector<bool> gone_;         // kept apart from Line: a release resets that
    std::vector<uint32_t> epochs_;   // bumped each time a line goes
    uint64_t stops_ = 0;
    uint64_t scl_pulses_ = 0;
    uint64_t last_scl_rise_ns_ = 0;
    uint64_t min_scl_period_ns_ = 0;
};

} // namespace caracara::sim
