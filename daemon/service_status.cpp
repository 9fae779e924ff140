#include "daemon/service_status.hpp"

#include "core/clock.hpp"

#include <systemd/sd-daemon.h>

namespace caracara {

void ServiceStatus::publish() const {
    const std::string state(vehicle_.readings().state_name());
    const std::string ks(vehicle_.readings().kill_source_name());
    // The faults someone must act on show on `systemctl status`'s Status: line.
    std::string faults;
    for (size_t i = 0; i < bus_.size(); ++i)
        for (Fault f : {Fault::WaterDetect, Fault::Overtemp})
            if (bus_.health().faults(i).has(f))
                faults += "; thruster " + std::to_string(i) + " " + std::string(fault_name(f));
    if (const std::string fs = failsafes_ ? failsafes_() : std::string(); !fs.empty())
        faults += "; FAILSAFE " + fs;
    if (vehicle_.readings().surfacing())
        faults += "; SURFACING";
    sd_notifyf(0, "STATUS=%s%s%s; profile %s; I2C bus %s; %zu thrusters%s", state.c_str(), ks.empty() ? "" : " by ",
               ks.c_str(), vehicle_.readings().profile().name.c_str(), std::string(bus_state_name(bus_.monitor().telemetry().state)).c_str(),
               bus_.size(), faults.c_str());
}

void ServiceStatus::start_watchdog() {
    uint64_t wd_usec = 0;
    if (sd_watchdog_enabled(0, &wd_usec) <= 0)
        return;
    // Four times a period, not the usual two: at half the period one unhealthy look (a loop
    // late by just over its second of grace) withheld a ping, and the next one, due exactly at
    // the deadline, lost the race to systemd's check under load. At a quarter, only a loop that
    // stays unhealthy for three looks in a row (no cycle for 3.5 s or more) is restarted.
    interval_us_ = wd_usec / 4;
    uint64_t now_us = 0;
    sd_event_now(event_, CLOCK_MONOTONIC, &now_us);
    sd_event_source* s = nullptr;
    if (sd_event_add_time(event_, &s, CLOCK_MONOTONIC, now_us + interval_us_, 1000, on_watchdog, this) < 0)
        return;
    sd_event_source_set_enabled(s, SD_EVENT_ON);
    watchdog_.reset(s);
}

int ServiceStatus::on_watchdog(sd_event_source* s, uint64_t usec, void* userdata) {
    auto* self = static_cast<ServiceStatus*>(userdata);
    // Only a control loop that keeps completing cycles keeps systemd from restarting us.
    // Judged now, not at `usec`: sd-event hands the time this source was due, and a cycle that
    // ended after it while the dispatch was late made the loop look 584 years stale
    // (caracarad restarted by its watchdog with the loop running, CI run of 86172d3).
    if (self->loop_.healthy(monotonic_ns()))
        sd_notify(0, "WATCHDOG=1");
    sd_event_source_set_time(s, usec + self->interval_us_);
    return 0;
}

void ServiceStatus::ready(const char* bus_name) const {
    sd_notifyf(0, "READY=1\nSTATUS=Thrusters zeroed; %s; serving %s", std::string(vehicle_.readings().state_name()).c_str(),
               bus_name);
}

void ServiceStatus::stopping() const { sd_notify(0, "STOPPING=1\nSTATUS=Thrusters zeroed; stopped"); }

} // namespace caracara
