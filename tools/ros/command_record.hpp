// What became of the ROS writers' commands, for /diagnostics: which writer holds the vehicle
// (the first that commands, until it stops for the command timeout or leaves) and every refusal,
// counted by kind, the last one spelled out. Written by the CommandSubscriber and its Pilots,
// read by the TelemetryPublisher, which hears of each change (so a refusal is on /diagnostics
// within a second).
#pragma once

#include "tools/ros/command_refusal.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <string>

namespace caracara::ros {

class CommandRecord {
public:
    // How long a holder that stopped sending keeps the vehicle: the daemon's CommandTimeoutMs.
    void set_timeout_ms(uint64_t ms) {
        if (ms) // 0: the property not read (caracarad takes 10 ms at least)
            timeout_ns_ = ms * 1'000'000;
    }
    uint64_t timeout_ms() const { return timeout_ns_ / 1'000'000; }
    void on_change(std::function<void()> f) { changed_ = std::move(f); }

    // `writer` (its GID as `ros2 topic info -v` prints it) commanded at `now_ns` (CLOCK_MONOTONIC).
    void commanded(const std::string& writer, uint64_t now_ns);
    // The holder left (its DDS writer unmatched).
    void left(const std::string& writer);
    void refused(const std::string& writer, CommandRefusal why, const std::string& detail, uint64_t now_ns);

    // The writer that holds the vehicle at `now_ns`, "" if none (never one, or it stopped).
    std::string holder(uint64_t now_ns) const;
    uint64_t refusals(CommandRefusal why) const { return counts_[static_cast<std::size_t>(why)]; }
    uint64_t refusals() const;
    const std::string& last_refusal() const { return last_refusal_; }
    uint64_t last_refusal_ns() const { return last_refusal_ns_; }

private:
    uint64_t timeout_ns_ = 500'000'000; // the daemon's default, until it is read
    std::string holder_;
    uint64_t holder_last_ns_ = 0;
    std::array<uint64_t, 4> counts_{};
    std::string last_refusal_;
    uint64_t last_refusal_ns_ = 0;
    std::function<void()> changed_;
};

} // namespace caracara::ros
