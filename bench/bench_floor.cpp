// caracara-bench-floor: the floor for the loop-rate, CPU and instruction figures. It issues
// the daemon's per-cycle transactions -- an order to every thruster, the configured status
// reads round robin, one Teensy poll frame -- through the same device seam (SimDeviceIo) and
// the same drivers to the same caracara-sim, and does nothing else: no event loop, no D-Bus,
// no safety logic, no telemetry.
//
//   caracara-bench-floor --socket PATH [--config FILE] --seconds S [--rate HZ [--burst-hz HZ]]
//   caracara-bench-floor --socket PATH [--config FILE] --cycles N          (for callgrind)
//   caracara-bench-floor --socket PATH [--config FILE] --burst N           (8 orders back to back)
//   caracara-bench-floor --socket PATH --config FILE --kill-seconds S      (kill switch -> output)
//
// --kill-seconds: the floor of the kill switch's path: the kill switch edge read and the kill
// output written through the same GPIO seam to the same simulator, nothing else, for S seconds
// (caracara-bench kill2output --floor 1 times it). Prints "ready" once both lines are held.
//
// Prints one JSON object: cycles, seconds, rate_hz, cpu_s (CLOCK_PROCESS_CPUTIME_ID).
#include "bench/bench_common.hpp"
#include "core/config.hpp"
#include "drivers/platform/hardware.hpp"
#include "drivers/platform/i2c_dev.hpp"
#include "drivers/platform/line_spec.hpp"
#include "drivers/platform/sim/sim_device_io.hpp"
#include "drivers/platform/spi_dev.hpp"
#include "drivers/devices/teensy_link.hpp"
#include "drivers/devices/thruster_driver.hpp"

#include <cstdio>
#include <cstdlib>
#include <poll.h>
#include <memory>
#include <string>
#include <vector>

using namespace caracara;
using namespace caracara::bench;

namespace {

long vm_hwm_kib() {
    FILE* f = std::fopen("/proc/self/status", "r");
    if (!f)
        return 0;
    char line[256];
    long kib = 0;
    while (std::fgets(line, sizeof line, f))
        if (std::sscanf(line, "VmHWM: %ld", &kib) == 1)
            break;
    std::fclose(f);
    return kib;
}

uint64_t cpu_ns() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<uint64_t>(ts.tv_sec) * 1'000'000'000ull + static_cast<uint64_t>(ts.tv_nsec);
}

// The kill switch's floor: edge -> read -> kill output, as KillSwitch and SafetyLines do it.
int kill_floor(const std::string& socket_path, const DaemonConfig& cfg, double seconds) {
    if (!cfg.gpio.kill_switch || !cfg.gpio.kill_output) {
        std::fprintf(stderr, "caracara-bench-floor: --kill-seconds needs gpio.kill_switch and gpio.kill_output\n");
        return 2;
    }
    Hardware hw;
    std::string err;
    if (!make_hardware("sim:" + socket_path, hw, err)) {
        std::fprintf(stderr, "caracara-bench-floor: %s\n", err.c_str());
        return 1;
    }
    auto in = hw.gpio->request(line_spec(*cfg.gpio.kill_switch), GpioMode::InputEdges, 0, err);
    auto out = in ? hw.gpio->request(line_spec(*cfg.gpio.kill_output), GpioMode::Output, 0, err) : nullptr;
    if (!in || !out || in->event_fd() < 0) {
        std::fprintf(stderr, "caracara-bench-floor: kill lines: %s\n", err.c_str());
        return 1;
    }
    std::printf("ready\n");
    std::fflush(stdout);
    long edges = 0;
    const uint64_t c0 = cpu_ns();
    const uint64_t end = mono_ns() + static_cast<uint64_t>(seconds * 1e9);
    for (uint64_t now = mono_ns(); now < end; now = mono_ns()) {
        pollfd p{in->event_fd(), POLLIN, 0};
        if (poll(&p, 1, static_cast<int>((end - now) / 1'000'000) + 1) <= 0)
            continue;
        if (in->drain_events() < 0)
            return 1;
        const int v = in->get();
        if (v < 0 || out->set(v) < 0)
            return 1;
        ++edges;
    }
    std::printf("{\"edges\": %ld, \"cpu_s\": %.6f}\n", edges, static_cast<double>(cpu_ns() - c0) / 1e9);
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    std::string socket_path, config_path;
    double seconds = 0, rate = 0, burst_hz = 0, kill_seconds = 0;
    long cycles_wanted = 0, burst = 0;
    for (int i = 1; i < argc; ++i) {
        std::string k = argv[i];
        if (i + 1 >= argc) {
            std::fprintf(stderr, "caracara-bench-floor: %s needs a value\n", k.c_str());
            return 2;
        }
        const char* v = argv[++i];
        if (k == "--socket") socket_path = v;
        else if (k == "--config") config_path = v;
        else if (k == "--seconds") seconds = std::strtod(v, nullptr);
        else if (k == "--rate") rate = std::strtod(v, nullptr);
        else if (k == "--cycles") cycles_wanted = std::strtol(v, nullptr, 10);
        else if (k == "--burst") burst = std::strtol(v, nullptr, 10);
        else if (k == "--burst-hz") burst_hz = std::strtod(v, nullptr);
        else if (k == "--kill-seconds") kill_seconds = std::strtod(v, nullptr);
        else {
            std::fprintf(stderr, "caracara-bench-floor: unknown option %s\n", k.c_str());
            return 2;
        }
    }
    ConfigResult cr = config_path.empty() ? parse_config_string("", "built-in defaults") : parse_config_file(config_path);
    if (!cr.ok()) {
        std::fprintf(stderr, "caracara-bench-floor: %s\n", cr.error().c_str());
        return 1;
    }
    const DaemonConfig& cfg = *cr.config;
    if (kill_seconds > 0)
        return kill_floor(socket_path, cfg, kill_seconds);
    SimDeviceIo io;
    if (int r = io.connect(socket_path); r < 0) {
        std::fprintf(stderr, "caracara-bench-floor: cannot connect to %s\n", socket_path.c_str());
        return 1;
    }
    I2cDev i2c(io, cfg.i2c.device);
    if (i2c.open() < 0) {
        std::fprintf(stderr, "caracara-bench-floor: cannot open %s\n", cfg.i2c.device.c_str());
        return 1;
    }
    MuxTracker mux;
    std::vector<std::unique_ptr<ThrusterDriver>> thrusters;
    for (const auto& tc : cfg.thrusters)
        thrusters.push_back(std::make_unique<ThrusterDriver>(i2c, mux, tc));
    SpiDev spi(io, cfg.spi.device, cfg.spi.spi);
    TeensyLink teensy(spi, cfg.spi.teensy);
    const bool have_teensy = spi.open() == 0;
    const unsigned sensors = static_cast<unsigned>(cfg.spi.teensy.limits.distance_sensor_count);
    const unsigned slots = 3 + (sensors ? 1 : 0);
    const uint32_t reads = cfg.control.status_reads_per_tick;

    if (burst > 0) {
        // The seam floor of a command: eight orders back to back, timed from before the first
        // request to the return of the last reply (the simulator replies at the end of the STOP).
        Rng rng(3);
        std::vector<double> us;
        for (long s = 0; s < burst; ++s) {
            sleep_ns(2'000'000 + rng.below(8'000'000));
            const int32_t v = s % 2 ? 3000 : -2000;
            const uint64_t t0 = mono_ns();
            for (auto& t : thrusters)
                t->send_order(v);
            us.push_back(static_cast<double>(mono_ns() - t0) / 1000.0);
        }
        for (auto& t : thrusters)
            t->send_order(0);
        std::printf("{\"burst_us\": %s, \"raw\": {\"burst_us\": %s}}\n", stats_json(us).c_str(), array_json(us).c_str());
        return 0;
    }

    size_t status_next = 0;
    unsigned poll_index = 0;
    auto cycle = [&]() {
        for (auto& t : thrusters)
            t->send_order(0);
        for (uint32_t k = 0; k < reads; ++k) {
            thrusters[status_next]->read_status();
            status_next = (status_next + 1) % thrusters.size();
        }
        if (have_teensy) {
            const unsigned slot = poll_index % slots;
            ++poll_index;
            if (slot < 3)
                teensy.get_orientation(static_cast<int>(slot));
            else
                teensy.get_distance(static_cast<int>((poll_index / slots) % sensors));
        }
    };

    long n = 0;
    const uint64_t c0 = cpu_ns();
    const uint64_t t0 = mono_ns();
    if (cycles_wanted > 0) {
        for (; n < cycles_wanted; ++n)
            cycle();
    } else {
        const uint64_t end = t0 + static_cast<uint64_t>(seconds * 1e9);
        const uint64_t period = rate > 0 ? static_cast<uint64_t>(1e9 / rate) : 0;
        // With --burst-hz, also what a command stream costs the daemon on the bus: eight
        // orders at that rate, between the cycles.
        const uint64_t burst_period = burst_hz > 0 ? static_cast<uint64_t>(1e9 / burst_hz) : 0;
        uint64_t next = t0, next_burst = t0 + burst_period / 2;
        while (mono_ns() < end) {
            if (!burst_period || next <= next_burst) {
                if (period)
                    sleep_until_ns(next);
                cycle();
                ++n;
                next += period;
            } else {
                sleep_until_ns(next_burst);
                for (auto& t : thrusters)
                    t->send_order(0);
                next_burst += burst_period;
            }
        }
    }
    const uint64_t t1 = mono_ns();
    const uint64_t c1 = cpu_ns();
    const double secs = static_cast<double>(t1 - t0) / 1e9;
    std::printf("{\"cycles\": %ld, \"seconds\": %.6f, \"rate_hz\": %.3f, \"cpu_s\": %.6f, \"teensy\": %s, "
                "\"status_reads\": %u, \"vmhwm_kib\": %ld}\n",
                n, secs, static_cast<double>(n) / secs, static_cast<double>(c1 - c0) / 1e9,
                have_teensy ? "true" : "false", reads, vm_hwm_kib());
    return 0;
}
