#include "daemon/commissioning/preflight_checks.hpp"

#include "drivers/platform/dive_files.hpp"
#include "drivers/protocol/seabotix.hpp"

#include <cstdarg>
#include <cstdio>
#include <ctime>
#include <sys/statvfs.h>
#include <sys/timex.h>
#include <unistd.h>

namespace caracara {

namespace {

// The clock is sane when it is past the date this build was made (CMake's configure time, or
// SOURCE_DATE_EPOCH for a package build): a board without a battery-backed clock that has not
// been set since boot reads an earlier time.
constexpr int64_t kBuildEpoch = CARACARA_BUILD_EPOCH;

__attribute__((format(printf, 1, 2))) std::string fmt(const char* f, ...) {
    char buf[256];
    va_list ap;
    va_start(ap, f);
    std::vsnprintf(buf, sizeof buf, f, ap);
    va_end(ap);
    return buf;
}

PreflightRow row(PreflightItem item, bool go, std::string observed, std::string advice) {
    return {item, -1, go, std::move(observed), go ? std::string() : std::move(advice)};
}

// A safety line's no-go when it is not configured or cannot be read (its [gpio.*] `table`).
PreflightRow unusable_line(PreflightItem item, bool configured, const std::string& table) {
    if (!configured)
        return row(item, false, "not configured", "configure [" + table + "]");
    return row(item, false, "cannot be read", "check its wiring and the chip and line of [" + table + "]");
}

// "2026-11-27 09:30 UTC"
std::string utc(time_t t) {
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", &tm);
    return buf;
}

// Bytes in the recorder directory's dives: what the writer counts against its bound
// (DiveWriter::do_open) and rotates out to stay in it.
uint64_t recorded_bytes(const std::string& dir) {
    uint64_t total = 0;
    for (const DiveFile& f : list_dive_files(dir))
        total += f.size;
    return total;
}

} // namespace

PreflightChecks::PreflightChecks(const DaemonConfig& config, const ThrusterBus& bus, const SafetyLines& lines)
    : config_(config), bus_(bus), lines_(lines) {}

std::string PreflightChecks::where(std::size_t i) const {
    const ThrusterConfig& c = config_.thrusters[i];
    std::string w = fmt("%s at MT 0x%02X", std::string(variant_name(c.variant)).c_str(), c.mt);
    return c.mux ? w + fmt(" behind mux 0x%02X channel %u", c.mux->addr7, c.mux->channel) : w;
}

PreflightRow PreflightChecks::thruster(std::size_t i, const ThrusterCounters& before) const {
    const ThrusterDriver& t = bus_.thruster(i);
    const ThrusterCounters& now = t.counters();
    PreflightRow r{PreflightItem::Thruster, int32_t(i), false, {}, {}};
    const uint64_t bad = now.bad_replies - before.bad_replies;
    const uint64_t failed = now.status_failures - before.status_failures - bad;
    if (bad > 0) {
        r.observed = fmt("answers, but not as configured: %llu garbled replies (%s)", (unsigned long long)bad,
                         std::string(codec_error_name(t.last_reply_error())).c_str());
        r.advice = "check that the controller at this address is the configured " + where(i) +
                   ", or set its variant and address in the config";
        return r;
    }
    if (failed > 0 || now.status_reads == before.status_reads || !t.online() || !t.last_status()) {
        r.observed = fmt("does not answer (%s): %llu of %llu status reads failed",
                         std::string(io_error_name(t.last_error())).c_str(), (unsigned long long)failed,
                         (unsigned long long)(failed + now.status_reads - before.status_reads));
        r.advice = "check its power, cable and address: configured as " + where(i);
        return r;
    }
    const ThrusterStatus& s = *t.last_status();
    std::string faults;
    for (Fault f : kAllFaults)
        if (s.faults.has(f))
            faults += (faults.empty() ? "" : ", ") + std::string(fault_name(f));
    if (!faults.empty()) {
        r.observed = "fault bits set: " + faults;
        r.advice = "inspect thruster " + std::to_string(i) + " (water: dry and reseal it; ground fault: power-cycle "
                   "after inspection); the dive's failsafes would act on it";
        return r;
    }
    r.observed = "answers as " + where(i) + ", no faults";
    if (s.temperature_c) {
        const unsigned temp = *s.temperature_c;
        r.observed += fmt(", %u C", temp);
        if (temp >= config_.failsafe.overtemp_clear_c) {
            r.advice = fmt("let it cool below %u C (failsafe.overtemp_clear_c) or check its temperature sensor",
                           unsigned(config_.failsafe.overtemp_clear_c));
            return r;
        }
    }
    r.go = true;
    return r;
}

PreflightRow PreflightChecks::bus() const {
    const BusTelemetry& tm = bus_.monitor().telemetry();
    const bool go = tm.state == BusState::Ok && !bus_.monitor().recovering();
    std::string seen = std::string(bus_state_name(tm.state)) + " (" + bus_.monitor().device() +
                       fmt(", %llu recoveries)", (unsigned long long)tm.recoveries);
    if (!go && !tm.last_error.empty())
        seen += ": " + tm.last_error;
    return row(PreflightItem::Bus, go, seen,
               "check the I2C wiring and the thrusters' power; caracarad recovers a locked bus by itself");
}

PreflightRow PreflightChecks::kill_switch() const {
    const std::optional<bool> set = lines_.kill_switch_level();
    if (!set)
        return unusable_line(PreflightItem::KillSwitch, lines_.kill_switch_configured(), "gpio.kill_switch");
    return row(PreflightItem::KillSwitch, !*set, *set ? "readable, pressed (kill)" : "readable, released",
               "release the kill switch");
}

PreflightRow PreflightChecks::kill_output() const {
    const std::optional<bool> back = lines_.kill_output_readback();
    if (!back)
        return unusable_line(PreflightItem::KillOutput, lines_.kill_output_configured(), "gpio.kill_output");
    const bool want = lines_.kill_output_intended();
    auto level = [](bool asserted) { return asserted ? "asserted (thrusters de-energized)" : "released (run enabled)"; };
    return row(PreflightItem::KillOutput, *back == want,
               std::string("reads ") + level(*back) + (*back == want ? ", as driven" : std::string(", driven ") + level(want)),
               "the line does not follow caracarad: check that nothing else drives it and its wiring");
}

PreflightRow PreflightChecks::config() const {
    if (config_file_.empty())
        return row(PreflightItem::Config, true, "built-in defaults (no file)", {});
    const ConfigResult cr = parse_config_file(config_file_);
    if (cr.ok())
        return row(PreflightItem::Config, true, config_file_ + " passes the checker", {});
    return row(PreflightItem::Config, false, cr.errors.front(), // "<file>: <key>: <problem>"
               "fix the file (caracarad --check-config " + config_file_ + "): caracarad will not start from it");
}

PreflightRow PreflightChecks::recorder() const {
    const RecorderSettings& rec = config_.recorder;
    if (!rec.enabled)
        return row(PreflightItem::Recorder, false, "disabled", "set recorder.enabled = true to record the dive");
    struct statvfs fs{};
    if (statvfs(rec.directory.c_str(), &fs) != 0 || access(rec.directory.c_str(), W_OK) != 0)
        return row(PreflightItem::Recorder, false, rec.directory + " missing or not writable",
                   "create " + rec.directory + " writable by caracarad, or fix recorder.directory");
    const uint64_t free_bytes = uint64_t(fs.f_bavail) * fs.f_frsize;
    const uint64_t bound = uint64_t(rec.max_total_mb) << 20;
    const uint64_t kept = recorded_bytes(rec.directory);
    const uint64_t need = bound > kept ? bound - kept : 0;
    const std::string seen = fmt("%llu MiB free, %llu MiB more wanted up to recorder.max_total_mb",
                                 (unsigned long long)(free_bytes >> 20), (unsigned long long)(need >> 20));
    return row(PreflightItem::Recorder, free_bytes >= need, rec.directory + ": " + seen,
               "free space on that filesystem or lower recorder.max_total_mb");
}

// Configured, not active: an active failsafe's cause (a fault bit, an unreachable thruster, the
// Teensy, the switch) is no-go in its own row.
PreflightRow PreflightChecks::failsafes() const {
    std::string warn_only, actions;
    for (FailsafeCondition c : kThrusterConditions) {
        const FailsafeAction a = config_.failsafe.rule(c).action;
        if (a == FailsafeAction::Warn)
            warn_only += (warn_only.empty() ? "" : ", ") + std::string(condition_name(c));
        actions += (actions.empty() ? "" : ", ") + std::string(condition_name(c)) + " " + std::string(action_name(a));
    }
    return row(PreflightItem::Failsafes, warn_only.empty(), actions,
               "only warn on " + warn_only + ": give each an action (exclude, surface or kill) in its "
               "[failsafe.<condition>] table");
}

PreflightRow PreflightChecks::clock() const {
    const time_t now = time(nullptr);
    // timedated's NTPSynchronized: the kernel's clock is disciplined (adjtimex, read only).
    struct timex tx{};
    const bool synced = adjtimex(&tx) >= 0 && !(tx.status & STA_UNSYNC) && tx.maxerror < 16'000'000;
    return row(PreflightItem::Clock, int64_t(now) >= kBuildEpoch,
               utc(now) + (synced ? ", synchronized" : ", not synchronized") + ", built " + utc(kBuildEpoch),
               "set the clock (timedatectl set-time, or reach an NTP server): dive files are named by it");
}

} // namespace caracara
