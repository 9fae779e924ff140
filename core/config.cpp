#include "core/config.hpp"

#include "core/failsafe_config.hpp"
#include "core/thruster_table.hpp"
#include "core/vehicle_config.hpp"
#include "core/toml_checker.hpp"
#include "core/toml_text.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <toml++/toml.h>
#include <type_traits>
#include <utility>

namespace caracara {

std::array<ThrusterConfig, kMotorCount> default_thrusters() {
    static constexpr std::array<uint8_t, kMotorCount> mts{0x52, 0x56, 0x58, 0x5A, 0x5C, 0x5E, 0x60, 0x62};
    std::array<ThrusterConfig, kMotorCount> t{};
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        t[i].mt = mts[i];
        t[i].variant = Variant::SeaBotix;
    }
    return t;
}

std::string ConfigResult::error() const {
    std::string out;
    for (const std::string& e : errors) {
        if (!out.empty())
            out += '\n';
        out += e;
    }
    return out;
}

SafetyConfig safety_config(const DaemonConfig& config) {
    SafetyConfig s;
    s.arming_delay_ns = ms_to_ns(config.control.arming_delay_ms);
    s.command_timeout_ns = ms_to_ns(config.control.command_timeout_ms);
    s.start_killed = !config.control.arm_at_start;
    return s;
}

namespace {

// One of an enum's names (core/enum_names.hpp): "must be \"a\" or \"b\", got \"c\"" otherwise.
template <typename E>
void choice(Checker& c, const toml::table& t, const std::string& p, std::string_view key, E& out) {
    std::string v;
    if (!c.string(t, p, key, v))
        return;
    if (const std::optional<E> parsed = parse_name<E>(v)) {
        out = *parsed;
        return;
    }
    std::string names;
    const auto& table = EnumNames<E>::table;
    for (std::size_t i = 0; i < table.size(); ++i)
        names += (i == 0 ? "\"" : i + 1 == table.size() ? " or \"" : ", \"") + std::string(table[i].name) + "\"";
    c.fail(p + std::string(key), "must be " + names + ", got \"" + v + "\"", t.get(key));
}

void parse_i2c(Checker& c, const toml::table& t, I2cSettings& out) {
    const std::string p = "i2c.";
    c.only_keys(t, p, {"device", "clock_hz", "timeout_ms", "retries"});
    c.path(t, p, "device", out.device);
    c.integer(t, p, "clock_hz", 1000, 3400000, out.clock_hz);
    c.integer(t, p, "timeout_ms", 10, 60000, out.timeout_ms);
    c.integer(t, p, "retries", 0, 16, out.retries);
}

void parse_spi(Checker& c, const toml::table& t, SpiSettings& out) {
    const std::string p = "spi.";
    c.only_keys(t, p,
                {"device", "speed_hz", "per_byte_delay_us", "busy_retries", "busy_delay_us", "servos",
                 "distance_sensors", "fitted", "silence_ms"});
    c.path(t, p, "device", out.device);
    c.integer(t, p, "speed_hz", 1000, 50000000, out.spi.speed_hz);
    c.integer(t, p, "per_byte_delay_us", 0, 10000, out.spi.byte_delay_us);
    c.integer(t, p, "busy_retries", 0, 255, out.teensy.retry.max_busy_retries);
    c.integer(t, p, "busy_delay_us", 0, 1000000, out.teensy.retry.busy_delay_us);
    // Servo and sensor ids travel as uint8, so at most 256 of each can be addressed.
    c.integer(t, p, "servos", 0, 256, out.teensy.limits.servo_count, "between 0 and 256 (ids are uint8)");
    c.integer(t, p, "distance_sensors", 0, 256, out.teensy.limits.distance_sensor_count,
              "between 0 and 256 (ids are uint8)");
    c.boolean(t, p, "fitted", out.fitted);
    c.integer(t, p, "silence_ms", 10, 60000, out.silence_ms);
}

// What an answering Teensy may take before its valid frame is in: two poll periods (one to send,
// one to take the answer) and a frame's busy resends.
uint64_t teensy_answer_ms(const DaemonConfig& cfg) {
    const uint64_t period_us = cfg.control.loop_rate_hz ? 1'000'000 / cfg.control.loop_rate_hz : 0;
    const uint64_t busy_us = uint64_t(cfg.spi.teensy.retry.max_busy_retries) * cfg.spi.teensy.retry.busy_delay_us;
    return (2 * period_us + busy_us + 999) / 1000;
}

// A silence_ms written shorter than that would kill a Teensy that answers as it should; unset,
// it is ten poll periods (200 ms at 50 Hz), at least 200 ms and twice that time.
void check_teensy_silence(Checker& c, const toml::table& root, DaemonConfig& cfg) {
    const uint64_t need_ms = teensy_answer_ms(cfg);
    if (!root["spi"]["silence_ms"]) {
        const uint64_t periods_ms = cfg.control.loop_rate_hz ? 10'000 / cfg.control.loop_rate_hz : 0;
        cfg.spi.silence_ms = static_cast<uint32_t>(std::max<uint64_t>({200, periods_ms, 2 * need_ms}));
        return;
    }
    if (uint64_t(cfg.spi.silence_ms) <= need_ms)
        c.fail("spi.silence_ms",
               std::string(kTeensySilenceError) + ": " + std::to_string(cfg.spi.silence_ms) +
                   " ms is within what an answering Teensy may take (two loop periods and the busy resends: " +
                   std::to_string(need_ms) + " ms)",
               root["spi"]["silence_ms"].node());
}

void parse_control(Checker& c, const toml::table& t, ControlSettings& out) {
    const std::string p = "control.";
    c.only_keys(t, p,
                {"loop_rate_hz", "status_reads_per_tick", "command_timeout_ms", "arming_delay_ms", "budget_policy",
                 "arm_at_start", "profile"});
    c.integer(t, p, "loop_rate_hz", 0, 1000, out.loop_rate_hz,
              "between 0 and 1000 (0 = as fast as the bus allows)");
    c.integer(t, p, "status_reads_per_tick", 1, static_cast<int64_t>(kMotorCount), out.status_reads_per_tick);
    c.integer(t, p, "command_timeout_ms", 10, 60000, out.command_timeout_ms);
    c.integer(t, p, "arming_delay_ms", 0, 60000, out.arming_delay_ms);
    c.boolean(t, p, "arm_at_start", out.arm_at_start);
    c.string(t, p, "profile", out.profile);
    choice(c, t, p, "budget_policy", out.budget_policy);
}

void parse_profiles(Checker& c, const toml::table& t, std::vector<ThrustProfile>& out) {
    std::vector<ThrustProfile> profiles;
    for (auto&& [k, v] : t) {
        const std::string key = "profiles." + std::string(k.str());
        double f = 0.0;
        if (const auto* iv = v.as_integer())
            f = static_cast<double>(iv->get());
        else if (const auto* fv = v.as_floating_point())
            f = fv->get();
        else {
            c.fail(key, "must be a scale factor (a number above 0, at most 1), got " + written(v), &v);
            continue;
        }
        if (!std::isfinite(f) || f <= 0.0 || f > 1.0) {
            c.fail(key, "must be a scale factor above 0 and at most 1, got " + written(v), &v);
            continue;
        }
        profiles.push_back({std::string(k.str()), f});
    }
    if (t.empty())
        c.fail("profiles", "names no profile; leave the table out for the built-in water = 1.0", &t);
    out = std::move(profiles);
}

std::optional<GpioLineSettings> parse_gpio_line(Checker& c, const toml::table& gpio, std::string_view role) {
    const std::string key = "gpio." + std::string(role);
    const toml::table* t = c.table(gpio, "gpio.", role);
    if (!t)
        return std::nullopt;
    const std::string p = key + ".";
    const std::size_t before = c.errors.size();
    c.only_keys(*t, p, {"chip", "line", "active_low"});
    GpioLineSettings s;
    c.string(*t, p, "chip", s.chip);
    c.boolean(*t, p, "active_low", s.active_low);
    const toml::node* ln = t->get("line");
    if (!ln) {
        c.fail(p + "line", "missing (a line name string or an offset integer)", t);
    } else if (ln->is_string()) {
        c.string(*t, p, "line", s.name);
    } else if (ln->is_integer()) {
        c.integer(*t, p, "line", 0, 65535, s.offset, "a line offset between 0 and 65535");
    } else {
        c.fail(p + "line", "must be a line name string or an offset integer, got " + written(*ln), ln);
    }
    if (c.errors.size() != before)
        return std::nullopt;
    return s;
}

std::string line_text(const GpioLineSettings& l) {
    return (l.offset ? "line " + std::to_string(*l.offset) : "line \"" + l.name + "\"") + " on " + l.chip;
}

void parse_gpio(Checker& c, const toml::table& t, GpioSettings& out) {
    c.only_keys(t, "gpio.", {"kill_switch", "kill_output", "power_off_output", "scl", "sda"});
    out.kill_switch = parse_gpio_line(c, t, "kill_switch");
    out.kill_output = parse_gpio_line(c, t, "kill_output");
    out.power_off_output = parse_gpio_line(c, t, "power_off_output");
    out.scl = parse_gpio_line(c, t, "scl");
    out.sda = parse_gpio_line(c, t, "sda");
    if (t.get("scl") && !t.get("sda"))
        c.fail("gpio.sda", "missing: gpio.scl and gpio.sda go together (the bus clear needs both)");
    if (t.get("sda") && !t.get("scl"))
        c.fail("gpio.scl", "missing: gpio.scl and gpio.sda go together (the bus clear needs both)");

    // One physical line cannot serve two roles.
    const std::array<std::pair<std::string_view, const std::optional<GpioLineSettings>*>, 5> roles{{
        {"kill_switch", &out.kill_switch},
        {"kill_output", &out.kill_output},
        {"power_off_output", &out.power_off_output},
        {"scl", &out.scl},
        {"sda", &out.sda},
    }};
    for (std::size_t i = 0; i < roles.size(); ++i) {
        for (std::size_t j = i + 1; j < roles.size(); ++j) {
            const auto& a = *roles[i].second;
            const auto& b = *roles[j].second;
            if (a && b && a->chip == b->chip && a->offset == b->offset && a->name == b->name)
                c.fail("gpio." + std::string(roles[j].first),
                       line_text(*b) + " is also used by gpio." + std::string(roles[i].first));
        }
    }
}

void parse_recovery(Checker& c, const toml::table& t, RecoverySettings& out) {
    const std::string p = "recovery.";
    c.only_keys(t, p,
                {"enabled", "attempts", "backoff_ms", "unbind_path", "bind_path", "driver_id", "device_wait_ms"});
    c.boolean(t, p, "enabled", out.enabled);
    c.integer(t, p, "attempts", 1, 10, out.attempts);
    c.integer(t, p, "backoff_ms", 0, 60000, out.backoff_ms);
    c.path(t, p, "unbind_path", out.unbind_path);
    c.path(t, p, "bind_path", out.bind_path);
    if (c.string(t, p, "driver_id", out.driver_id, true) &&
        out.driver_id.find_first_of("/ \t\n") != std::string::npos)
        c.fail(p + "driver_id", "must be a device name such as \"fe804000.i2c\", got \"" + out.driver_id + "\"",
               t.get("driver_id"));
    c.integer(t, p, "device_wait_ms", 0, 60000, out.device_wait_ms);
}

void parse_recorder(Checker& c, const toml::table& t, RecorderSettings& out) {
    const std::string p = "recorder.";
    c.only_keys(t, p, {"enabled", "directory", "max_total_mb"});
    c.boolean(t, p, "enabled", out.enabled);
    c.path(t, p, "directory", out.directory);
    c.integer(t, p, "max_total_mb", 1, 1048576, out.max_total_mb);
}

void parse_realtime(Checker& c, const toml::table& t, RealtimeSettings& out) {
    const std::string p = "realtime.";
    c.only_keys(t, p, {"enabled", "policy", "loop_priority", "bus_priority", "teensy_priority", "lock_memory"});
    c.boolean(t, p, "enabled", out.enabled);
    c.boolean(t, p, "lock_memory", out.lock_memory);
    choice(c, t, p, "policy", out.policy);
    // 1..49: below PREEMPT_RT's interrupt threads (50) and the kernel's own 99.
    const char* range = "between 1 and 49 (below the kernel's interrupt threads at 50)";
    // Absent keys keep their (valid) defaults; only a refused value skips the order check.
    auto priority = [&](std::string_view key, uint32_t& v) {
        return c.integer(t, p, key, 1, 49, v, range) || !t.get(key);
    };
    const bool loop_ok = priority("loop_priority", out.loop_priority);
    const bool bus_ok = priority("bus_priority", out.bus_priority);
    const bool teensy_ok = priority("teensy_priority", out.teensy_priority);
    // The loop carries the kill: a worker at or above it could hold the CPU the kill needs.
    if (loop_ok && bus_ok && out.bus_priority >= out.loop_priority)
        c.fail(p + "bus_priority",
               "must be below realtime.loop_priority (" + std::to_string(out.loop_priority) +
                   "): a kill on the loop preempts the wire",
               t.get("bus_priority"));
    if (loop_ok && teensy_ok && out.teensy_priority >= out.loop_priority)
        c.fail(p + "teensy_priority",
               "must be below realtime.loop_priority (" + std::to_string(out.loop_priority) +
                   "): a kill on the loop preempts the Teensy's frames",
               t.get("teensy_priority"));
}

void parse_commissioning(Checker& c, const toml::table& t, CommissioningSettings& out) {
    const std::string p = "commissioning.";
    c.only_keys(t, p, {"motor_test_limit", "motor_test_keepalive_ms", "detect_pulse_value", "detect_pulse_ms",
                       "detect_threshold_mrad", "detect_settle_mrad", "detect_settle_ms", "detect_settle_timeout_ms"});
    c.integer(t, p, "motor_test_limit", 1, kMotorMax, out.motor_test_limit);
    c.integer(t, p, "motor_test_keepalive_ms", 50, 500, out.motor_test_keepalive_ms);
    c.integer(t, p, "detect_pulse_value", 100, 5000, out.detect_pulse_value);
    c.integer(t, p, "detect_pulse_ms", 100, 3000, out.detect_pulse_ms);
    c.integer(t, p, "detect_threshold_mrad", 1, 500, out.detect_threshold_mrad);
    c.integer(t, p, "detect_settle_mrad", 1, 500, out.detect_settle_mrad);
    c.integer(t, p, "detect_settle_ms", 100, 5000, out.detect_settle_ms);
    c.integer(t, p, "detect_settle_timeout_ms", 1000, 60000, out.detect_settle_timeout_ms);
}

} // namespace

ConfigResult parse_config_string(std::string_view text, std::string_view source) {
    ConfigResult r;
    const std::string prefix = source.empty() ? std::string() : std::string(source) + ": ";
    if (std::string e = non_ascii_outside_comments(text); !e.empty()) {
        r.errors.push_back(prefix + e);
        return r;
    }
    toml::table root;
    try {
        root = toml::parse(text, source);
    } catch (const toml::parse_error& e) {
        r.errors.push_back(prefix + "line " + std::to_string(e.source().begin.line) + ", column " +
                           std::to_string(e.source().begin.column) + ": " + std::string(e.description()));
        return r;
    }

    Checker c;
    DaemonConfig cfg;
    // [sim] belongs to caracara-sim, which reads the same file; it is not checked here.
    c.only_keys(root, "", {"i2c", "spi", "thruster", "mixing", "control", "gpio", "recovery", "profiles", "recorder", "failsafe",
                       "realtime", "commissioning", "sim", "vehicle"});
    if (const toml::table* t = c.table(root, "", "i2c"))
        parse_i2c(c, *t, cfg.i2c);
    if (const toml::table* t = c.table(root, "", "spi"))
        parse_spi(c, *t, cfg.spi);
    parse_thrusters(c, root, cfg.thrusters);
    // [vehicle] and the thrusters' position / direction are caracara-ros's and caracara-sim's (a
    // Wrench in newtons); the daemon checks them so one file is wrong in one place.
    VehicleGeometry geometry;
    if (std::string e = parse_vehicle(root, geometry); !e.empty()) {
        const auto at = e.find(": ");
        c.fail(e.substr(0, at), e.substr(at + 2));
    }
    if (const toml::table* t = c.table(root, "", "mixing"))
        parse_mixing(c, *t, cfg.mixing);
    if (const toml::table* t = c.table(root, "", "control"))
        parse_control(c, *t, cfg.control);
    if (const toml::table* t = c.table(root, "", "gpio"))
        parse_gpio(c, *t, cfg.gpio);
    if (const toml::table* t = c.table(root, "", "recovery"))
        parse_recovery(c, *t, cfg.recovery);
    if (const toml::table* t = c.table(root, "", "profiles"))
        parse_profiles(c, *t, cfg.profiles);
    if (const toml::table* t = c.table(root, "", "recorder"))
        parse_recorder(c, *t, cfg.recorder);
    if (const toml::table* t = c.table(root, "", "failsafe"))
        parse_failsafe(c, *t, cfg.failsafe);
    if (const toml::table* t = c.table(root, "", "realtime"))
        parse_realtime(c, *t, cfg.realtime);
    if (const toml::table* t = c.table(root, "", "commissioning"))
        parse_commissioning(c, *t, cfg.commissioning);
    c.table(root, "", "sim");
    if (!cfg.profiles.empty() && !find_profile(cfg, cfg.control.profile)) {
        c.fail("control.profile", "\"" + cfg.control.profile + "\" is not a profile; known: " + profile_names(cfg),
               root["control"]["profile"].node());
    }

    if (c.errors.empty())
        check_teensy_silence(c, root, cfg);

    // Only when neither line is given: one without the other is already reported.
    if (cfg.recovery.enabled && !root["gpio"]["scl"] && !root["gpio"]["sda"])
        c.fail("recovery.enabled", "bus recovery needs gpio.scl and gpio.sda", root["recovery"]["enabled"].node());

    if (!c.errors.empty()) {
        for (std::string& e : c.errors)
            r.errors.push_back(prefix + e);
        return r;
    }
    r.config = std::move(cfg);
    return r;
}

const ThrustProfile* find_profile(const DaemonConfig& config, std::string_view name) {
    for (const auto& p : config.profiles)
        if (p.name == name)
            return &p;
    return nullptr;
}

std::string profile_names(const DaemonConfig& config) {
    std::string known;
    for (const auto& p : config.profiles)
        known += (known.empty() ? "" : ", ") + p.name;
    return known;
}

ConfigResult parse_config_file(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) {
        const int err = errno;
        ConfigResult r;
        r.errors.push_back(path + ": cannot read: " + std::strerror(err));
        return r;
    }
    std::ostringstream ss;
    ss << f.rdbuf();
    return parse_config_string(ss.str(), path);
}

} // namespace caracara
