// The preflight's judgements (docs/commissioning.md, Preflight): each item of the go/no-go table
// from state the daemon already has, read only. The thrusters are judged over a window: each must
// have answered status reads in its configured variant's format, none garbled, since `before`.
#pragma once

#include "core/config.hpp"
#include "core/preflight_row.hpp"
#include "daemon/bus/thruster_bus.hpp"
#include "daemon/safety/safety_lines.hpp"

#include <cstddef>
#include <string>

namespace caracara {

class PreflightChecks final {
public:
    PreflightChecks(const DaemonConfig& config, const ThrusterBus& bus, const SafetyLines& lines);
    PreflightRow thruster(std::size_t i, const ThrusterCounters& before) const;
    PreflightRow bus() const;
    PreflightRow kill_switch() const;
    PreflightRow kill_output() const;
    PreflightRow config() const;
    PreflightRow recorder() const;
    PreflightRow failsafes() const;
    PreflightRow clock() const;
    // The file caracarad was started from ("" for the built-in defaults): the checker runs on it.
    void set_config_file(std::string path) { config_file_ = std::move(path); }

private:
    std::string where(std::size_t i) const; // "MT 0x52 on the main bus", "MT 0x52 behind mux 0x70 channel 1"

    const DaemonConfig& config_;
    const ThrusterBus& bus_;
    const SafetyLines& lines_;
    std::string config_file_;
};

} // namespace caracara
