// caracarad's configuration checker (core/config.hpp) and caracara-sim's reader of the same
// file (sim/sim_config.hpp) fed arbitrary text. Invariants: an accepted file gives values in
// their documented ranges and a thruster set the drivers accept; a refused one gives no
// config and messages that name where (the source prefix, a real line); and a file caracarad
// accepts (without a [sim] table of its own) describes the same thrusters to the simulator.
#include "core/config.hpp"
#include "core/thruster_config.hpp"
#include "fuzz/check.hpp"
#include "sim/sim_config.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <string_view>

using namespace caracara;

namespace {

bool in(int64_t v, int64_t lo, int64_t hi) { return v >= lo && v <= hi; }

void check_line(const GpioLineSettings& l, const char* role) {
    FUZZ_CHECK(!l.chip.empty() && (l.offset.has_value() != !l.name.empty()), "gpio.%s: chip/line/offset", role);
    FUZZ_CHECK(!l.offset || *l.offset <= 65535, "gpio.%s offset", role);
}

void check_accepted(const DaemonConfig& c) {
    FUZZ_CHECK(c.i2c.device.starts_with('/') && in(c.i2c.clock_hz, 1000, 3400000), "i2c");
    FUZZ_CHECK(!c.i2c.timeout_ms || in(*c.i2c.timeout_ms, 10, 60000), "i2c.timeout_ms");
    FUZZ_CHECK(!c.i2c.retries || *c.i2c.retries <= 16, "i2c.retries");
    FUZZ_CHECK(c.spi.device.starts_with('/') && in(c.spi.spi.speed_hz, 1000, 50000000) &&
                   c.spi.spi.byte_delay_us <= 10000 && c.spi.teensy.retry.busy_delay_us <= 1000000,
               "spi");
    FUZZ_CHECK(in(c.spi.teensy.limits.servo_count, 0, 256) && in(c.spi.teensy.limits.distance_sensor_count, 0, 256),
               "spi servos/distance_sensors");
    FUZZ_CHECK(validate_thruster_set(c.thrusters).empty(), "accepted thrusters refused by the drivers' rules: %s",
               validate_thruster_set(c.thrusters).c_str());
    for (const auto& row : c.mixing)
        for (double v : row)
            FUZZ_CHECK(std::isfinite(v) && v >= -1.0 && v <= 1.0, "mixing value %g", v);
    const ControlSettings& k = c.control;
    FUZZ_CHECK(k.loop_rate_hz <= 1000 && in(k.status_reads_per_tick, 1, 8) && in(k.command_timeout_ms, 10, 60000) &&
                   k.arming_delay_ms <= 60000,
               "control");
    FUZZ_CHECK(!c.profiles.empty() && find_profile(c, k.profile), "profile \"%s\" not among the profiles",
               k.profile.c_str());
    for (const ThrustProfile& p : c.profiles)
        FUZZ_CHECK(std::isfinite(p.factor) && p.factor > 0.0 && p.factor <= 1.0, "profile %s = %g", p.name.c_str(),
                   p.factor);
    const GpioSettings& g = c.gpio;
    FUZZ_CHECK(g.scl.has_value() == g.sda.has_value(), "scl without sda or the reverse");
    FUZZ_CHECK(!c.recovery.enabled || (g.scl && g.sda), "recovery enabled without the bus-clear lines");
    const std::optional<GpioLineSettings>* lines[] = {&g.kill_switch, &g.kill_output, &g.power_off_output, &g.scl,
                                                      &g.sda};
    const char* roles[] = {"kill_switch", "kill_output", "power_off_output", "scl", "sda"};
    for (std::size_t i = 0; i < 5; ++i) {
        if (!*lines[i])
            continue;
        check_line(**lines[i], roles[i]);
        for (std::size_t j = 0; j < i; ++j) {
            const auto& a = **lines[i];
            if (*lines[j])
                FUZZ_CHECK(!(a.chip == (*lines[j])->chip && a.offset == (*lines[j])->offset && a.name == (*lines[j])->name),
                           "gpio.%s and gpio.%s are one line", roles[j], roles[i]);
        }
    }
    const RecoverySettings& r = c.recovery;
    FUZZ_CHECK(in(r.attempts, 1, 10) && r.backoff_ms <= 60000 && r.device_wait_ms <= 60000 &&
                   r.unbind_path.starts_with('/') && r.bind_path.starts_with('/') &&
                   r.driver_id.find_first_of("/ \t\n") == std::string::npos,
               "recovery");
}

void check_sim(const sim::SimConfig& s) {
    FUZZ_CHECK(in(s.i2c_clock_hz, 1000, 3400000) && s.rebind_delay_ms <= 60000, "sim i2c clock / rebind delay");
    for (const sim::ThrusterSpec& t : s.thrusters) {
        FUZZ_CHECK(is_valid_mt(t.mt) && t.mux_channel <= 3, "sim thruster mt %#x channel %u", t.mt, t.mux_channel);
        FUZZ_CHECK(!t.mux_addr || is_valid_mux_addr7(*t.mux_addr), "sim mux address");
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    const ConfigResult r = parse_config_string(text, "fuzz.toml");
    FUZZ_CHECK(r.ok() == r.errors.empty(), "ok %d with %zu errors", r.ok(), r.errors.size());
    const long lines = std::count(text.begin(), text.end(), '\n') + 1;
    for (const std::string& e : r.errors) {
        FUZZ_CHECK(e.starts_with("fuzz.toml: ") && e.size() > 11, "message without its source: %s", e.c_str());
        // A trailing "(line N)" and a leading "line N, column M" point into the text (the
        // message between may quote the user's text, "(line " included).
        std::size_t at = std::string::npos;
        if (e.ends_with(")") && (at = e.rfind("(line ")) != std::string::npos)
            at += 6;
        else if (e.starts_with("fuzz.toml: line "))
            at = 16;
        if (at != std::string::npos) {
            const long n = std::strtol(e.c_str() + at, nullptr, 10);
            FUZZ_CHECK(n >= 1 && n <= lines, "line %ld of a %ld-line text: %s", n, lines, e.c_str());
        }
    }
    if (r.ok())
        check_accepted(*r.config);

    sim::SimConfig s;
    std::string error;
    const bool sim_ok = sim::parse_sim_config(text, s, error);
    FUZZ_CHECK(sim_ok == error.empty(), "simulator: ok %d, error \"%s\"", sim_ok, error.c_str());
    if (sim_ok)
        check_sim(s);
    // One file describes both sides: what caracarad accepts, the simulator reads the same way.
    if (r.ok() && text.find("sim") == std::string::npos) {
        FUZZ_CHECK(sim_ok, "caracarad accepts, the simulator refuses: %s", error.c_str());
        const DaemonConfig& c = *r.config;
        FUZZ_CHECK(s.i2c_clock_hz == c.i2c.clock_hz && s.i2c_device == c.i2c.device && s.spi_device == c.spi.device,
                   "i2c/spi settings differ");
        FUZZ_CHECK(s.thrusters.size() == c.thrusters.size(), "%zu thrusters for the simulator", s.thrusters.size());
        for (std::size_t i = 0; i < c.thrusters.size(); ++i) {
            const ThrusterConfig& d = c.thrusters[i];
            const sim::ThrusterSpec& t = s.thrusters[i];
            const bool legacy = t.variant == sim::ThrusterVariant::Legacy;
            FUZZ_CHECK(t.mt == d.mt && legacy == (d.variant == Variant::Legacy) &&
                           t.mux_addr.has_value() == d.mux.has_value() &&
                           (!d.mux || (*t.mux_addr == d.mux->addr7 && t.mux_channel == d.mux->channel)),
                       "thruster %zu differs between caracarad and the simulator", i);
        }
    }
    return 0;
}
