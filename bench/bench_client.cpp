// caracara-bench: the D-Bus side of the benchmarks (bench/run.py drives it). One sd-bus
// connection, synchronous calls, CLOCK_MONOTONIC around them; the simulator's wire log
// (stamped with the same clock at the end of each message, and at each GPIO line change)
// tells when the wire saw what.
//
//   caracara-bench rtt        --bus ADDR [--calls N] [--warmup N] [--settle-us US]
//   caracara-bench cmd2wire   --bus ADDR [--samples N] [--phase-ms MS] [--seed S]
//   caracara-bench kill2wire  --bus ADDR [--samples N] [--source dbus|switch] [--phase-ms MS]
//   caracara-bench kill2output --bus ADDR [--samples N] [--source dbus|switch] [--phase-ms MS] [--floor 1]
//   caracara-bench cycles     --bus ADDR --seconds S
//   caracara-bench stream     --bus ADDR --hz H --seconds S
//   caracara-bench wait-ready --bus ADDR [--timeout-ms MS]   (arms a daemon that started killed)
//
// Every measuring command prints one JSON object on stdout.
#include "bench/bench_common.hpp"
#include "drivers/sdbus/sdbus.hpp"
#include "drivers/protocol/seabotix.hpp"

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>
#include <string>
#include <vector>

using namespace caracara;
using namespace caracara::bench;

namespace {

constexpr const char* kVehicle = "org.caracara.Vehicle1";
constexpr const char* kVehiclePath = "/org/caracara/Vehicle1";
constexpr const char* kSim = "org.caracara.Simulator1";
constexpr const char* kSimPath = "/org/caracara/Simulator1";
constexpr uint64_t kCallTimeoutUs = 10'000'000;

using Values = std::array<int32_t, 8>;
// Two command sets that differ in every motor and stay inside the 8-motor budget (4200),
// so the daemon sends them unscaled and every thruster's SPEED byte changes between them.
constexpr Values kSetA{3000, 3000, 3000, 3000, 3000, 3000, 3000, 3000};
constexpr Values kSetB{-2000, -2000, -2000, -2000, -2000, -2000, -2000, -2000};

[[noreturn]] void die(const char* what, int r) {
    std::fprintf(stderr, "caracara-bench: %s: %s\n", what, std::strerror(r < 0 ? -r : r));
    std::exit(1);
}

struct Entry {
    uint64_t index = 0;
    uint64_t time_ns = 0;
    uint64_t txn = 0;
    std::string bus;
    uint16_t addr = 0;
    bool read = false;
    std::vector<uint8_t> data;
    std::string result;
};

class Client {
public:
    explicit Client(const std::string& address) {
        dbus::BusChoice c{dbus::BusChoice::Kind::Address, address};
        if (int r = dbus::open_bus(c, "caracara-bench", bus_); r < 0)
            die("cannot connect to the bus", r);
    }
    sd_bus* bus() { return bus_.get(); }

    // Builds a SetThrust call (not timed), so the timed part is the call alone.
    dbus::MessagePtr set_thrust_msg(const Values& v) {
        sd_bus_message* m = nullptr;
        int r = sd_bus_message_new_method_call(bus(), &m, kVehicle, kVehiclePath, kVehicle, "SetThrust");
        if (r >= 0)
            r = sd_bus_message_append_array(m, 'i', v.data(), v.size() * sizeof(int32_t));
        if (r < 0)
            die("building SetThrust", r);
        return dbus::MessagePtr(m);
    }
    dbus::MessagePtr method_msg(const char* dest, const char* path, const char* iface, const char* member) {
        sd_bus_message* m = nullptr;
        if (int r = sd_bus_message_new_method_call(bus(), &m, dest, path, iface, member); r < 0)
            die("building a call", r);
        return dbus::MessagePtr(m);
    }
    // Sends and waits; returns 0 or the negative errno, with the D-Bus error name in `error`.
    int call(dbus::MessagePtr& m, std::string* error = nullptr, dbus::MessagePtr* reply_out = nullptr) {
        sd_bus_error err = SD_BUS_ERROR_NULL;
        sd_bus_message* reply = nullptr;
        int r = sd_bus_call(bus(), m.get(), kCallTimeoutUs, &err, &reply);
        if (r < 0 && error)
            *error = err.name ? err.name : std::strerror(-r);
        sd_bus_error_free(&err);
        if (reply_out)
            reply_out->reset(reply);
        else
            sd_bus_message_unref(reply);
        return r < 0 ? r : 0;
    }
    int set_thrust(const Values& v, std::string* error = nullptr) {
        auto m = set_thrust_msg(v);
        return call(m, error);
    }
    int vehicle_call(const char* member, std::string* error = nullptr) {
        auto m = method_msg(kVehicle, kVehiclePath, kVehicle, member);
        return call(m, error);
    }
    int set_kill_switch(bool on) {
        auto m = method_msg(kSim, kSimPath, kSim, "SetKillSwitch");
        if (int r = sd_bus_message_append(m.get(), "b", static_cast<int>(on)); r < 0)
            die("SetKillSwitch", r);
        std::string e;
        int r = call(m, &e);
        if (r < 0)
            std::fprintf(stderr, "caracara-bench: SetKillSwitch: %s\n", e.c_str());
        return r;
    }
    std::string get_string(const char* dest, const char* path, const char* iface, const char* member) {
        sd_bus_error err = SD_BUS_ERROR_NULL;
        char* s = nullptr;
        int r = sd_bus_get_property_string(bus(), dest, path, iface, member, &err, &s);
        sd_bus_error_free(&err);
        if (r < 0)
            return {};
        std::string out = s;
        std::free(s);
        return out;
    }
    // A property of a trivial type: 0 or the negative errno.
    template <typename T>
    int read_trivial(const char* dest, const char* path, const char* iface, const char* member, char type, T* v) {
        sd_bus_error err = SD_BUS_ERROR_NULL;
        int r = sd_bus_get_property_trivial(bus(), dest, path, iface, member, &err, type, v);
        sd_bus_error_free(&err);
        return r < 0 ? r : 0;
    }
    template <typename T>
    T get_trivial(const char* dest, const char* path, const char* iface, const char* member, char type) {
        T v{};
        if (int r = read_trivial(dest, path, iface, member, type, &v); r < 0)
            die(member, r);
        return v;
    }
    std::string state() { return get_string(kVehicle, kVehiclePath, kVehicle, "State"); }
    uint64_t cycles() { return get_trivial<uint64_t>(kVehicle, kVehiclePath, kVehicle, "Cycles", 't'); }

    // GetWireLog(since): appends the entries to `out`, returns the next index.
    uint64_t wire_log(uint64_t since, std::vector<Entry>* out) {
        auto m = method_msg(kSim, kSimPath, kSim, "GetWireLog");
        if (int r = sd_bus_message_append(m.get(), "t", since); r < 0)
            die("GetWireLog", r);
        dbus::MessagePtr reply;
        std::string e;
        if (int r = call(m, &e, &reply); r < 0) {
            std::fprintf(stderr, "caracara-bench: GetWireLog: %s\n", e.c_str());
            std::exit(1);
        }
        sd_bus_message* rp = reply.get();
        uint64_t next = 0;
        int r = sd_bus_message_read(rp, "t", &next);
        if (r >= 0)
            r = sd_bus_message_enter_container(rp, 'a', "(tttsqbayays)");
        while (r >= 0) {
            r = sd_bus_message_enter_container(rp, 'r', "tttsqbayays");
            if (r <= 0)
                break;
            Entry en;
            const char* busname = nullptr;
            int rd = 0;
            r = sd_bus_message_read(rp, "tttsqb", &en.index, &en.time_ns, &en.txn, &busname, &en.addr, &rd);
            const void* p = nullptr;
            size_t n = 0;
            if (r >= 0)
                r = sd_bus_message_read_array(rp, 'y', &p, &n);
            if (r >= 0 && n)
                en.data.assign(static_cast<const uint8_t*>(p), static_cast<const uint8_t*>(p) + n);
            if (r >= 0)
                r = sd_bus_message_read_array(rp, 'y', &p, &n); // miso: not needed
            const char* res = nullptr;
            if (r >= 0)
                r = sd_bus_message_read(rp, "s", &res);
            if (r >= 0)
                r = sd_bus_message_exit_container(rp);
            if (r < 0)
                break;
            en.bus = busname ? busname : "";
            en.read = rd != 0;
            en.result = res ? res : "";
            if (out)
                out->push_back(std::move(en));
        }
        if (r < 0)
            die("parsing the wire log", r);
        return next;
    }
    uint64_t wire_next() { return wire_log(UINT64_MAX, nullptr); }

    // Also arms a daemon that started killed (kill source "start"), as a pilot would, and one
    // the pilot-lost failsafe killed after an earlier bench client, the last pilot, left (source
    // "failsafe": the bench provokes no other failsafe).
    bool wait_ready(uint64_t timeout_ns) {
        const uint64_t end = mono_ns() + timeout_ns;
        while (mono_ns() < end) {
            const std::string s = state();
            if (s == "ready")
                return true;
            const std::string source = s == "killed" ? get_string(kVehicle, kVehiclePath, kVehicle, "KillSource") : "";
            if (source == "start" || source == "failsafe")
                vehicle_call("ClearKill");
            sleep_ns(1'000'000);
        }
        return false;
    }

private:
    dbus::BusPtr bus_;
};

struct Args {
    std::string command;
    std::string bus;
    long calls = 10000;
    long warmup = 500;
    long samples = 500;
    double phase_ms = 20;
    double seconds = 5;
    double hz = 20;
    double timeout_ms = 10000;
    double settle_us = 2000;
    uint64_t seed = 1;
    std::string source = "dbus";
    bool floor = false; // kill2output --source switch against caracara-bench-floor --kill-seconds
};

Args parse(int argc, char** argv) {
    Args a;
    if (argc < 2) {
        std::fprintf(stderr, "usage: caracara-bench rtt|cmd2wire|kill2wire|kill2output|cycles|stream|wait-ready --bus ADDR ...\n");
        std::exit(2);
    }
    a.command = argv[1];
    for (int i = 2; i < argc; ++i) {
        std::string k = argv[i];
        if (i + 1 >= argc) {
            std::fprintf(stderr, "caracara-bench: %s needs a value\n", k.c_str());
            std::exit(2);
        }
        const char* v = argv[++i];
        if (k == "--bus") a.bus = v;
        else if (k == "--calls") a.calls = std::strtol(v, nullptr, 10);
        else if (k == "--warmup") a.warmup = std::strtol(v, nullptr, 10);
        else if (k == "--samples") a.samples = std::strtol(v, nullptr, 10);
        else if (k == "--phase-ms") a.phase_ms = std::strtod(v, nullptr);
        else if (k == "--seconds") a.seconds = std::strtod(v, nullptr);
        else if (k == "--hz") a.hz = std::strtod(v, nullptr);
        else if (k == "--timeout-ms") a.timeout_ms = std::strtod(v, nullptr);
        else if (k == "--settle-us") a.settle_us = std::strtod(v, nullptr);
        else if (k == "--seed") a.seed = std::strtoull(v, nullptr, 10);
        else if (k == "--source") a.source = v;
        else if (k == "--floor") a.floor = std::strtol(v, nullptr, 10) != 0;
        else {
            std::fprintf(stderr, "caracara-bench: unknown option %s\n", k.c_str());
            std::exit(2);
        }
    }
    if (a.bus.empty()) {
        std::fprintf(stderr, "caracara-bench: --bus ADDR is required\n");
        std::exit(2);
    }
    return a;
}

// --- 1. SetThrust round trip against Peer.Ping ---------------------------------------------

int cmd_rtt(const Args& a) {
    Client c(a.bus);
    if (!c.wait_ready(10'000'000'000ull)) {
        std::fprintf(stderr, "caracara-bench: the vehicle is not ready\n");
        return 1;
    }
    long errors = 0;
    std::string last_error;
    auto set_thrust = [&](long i) {
        auto m = c.set_thrust_msg(i % 2 ? kSetA : kSetB);
        const uint64_t t0 = mono_ns();
        if (c.call(m, &last_error) < 0)
            ++errors;
        return static_cast<double>(mono_ns() - t0) / 1000.0;
    };
    auto ping = [&] {
        auto m = c.method_msg(kVehicle, kVehiclePath, "org.freedesktop.DBus.Peer", "Ping");
        const uint64_t t0 = mono_ns();
        c.call(m);
        return static_cast<double>(mono_ns() - t0) / 1000.0;
    };
    // Each call is made after a settle gap, so SetThrust and Ping both meet the daemon with the
    // previous command's orders out (about 0.2 ms with the simulator answering at once, 3 ms on
    // a 100 kHz wire), as a script commanding at 10-50 Hz meets it; the pair's order alternates.
    // Back to back, a Ping lands in the eight orders its SetThrust started, while the daemon is
    // awake and checks for messages between transactions, and the next SetThrust lands on a
    // daemon gone back to sleep: that compares unlike states (the "back_to_back" diagnostic).
    const uint64_t kSettleNs = static_cast<uint64_t>(a.settle_us * 1000.0);
    auto pairs = [&](long n, std::vector<double>& st, std::vector<double>& pg) {
        for (long i = 0; i < a.warmup + n; ++i) {
            double ts = 0, tp = 0;
            sleep_ns(kSettleNs);
            if (i % 2) {
                ts = set_thrust(i);
                sleep_ns(kSettleNs);
                tp = ping();
            } else {
                tp = ping();
                sleep_ns(kSettleNs);
                ts = set_thrust(i);
            }
            if (i >= a.warmup) {
                st.push_back(ts);
                pg.push_back(tp);
            }
        }
    };
    std::vector<double> st, pg, st_b2b, pg_b2b, refused, pg_killed;
    st.reserve(static_cast<size_t>(a.calls));
    pg.reserve(static_cast<size_t>(a.calls));
    pairs(a.calls, st, pg);
    const long n_diag = std::max(1L, a.calls / 4);
    for (long i = 0; i < a.warmup + n_diag; ++i) {
        const double ts = set_thrust(i);
        const double tp = ping();
        if (i >= a.warmup) {
            st_b2b.push_back(ts);
            pg_b2b.push_back(tp);
        }
    }
    // Diagnostic: while the vehicle is killed SetThrust is refused (Killed) after the same
    // parsing and validation, with no orders and no PropertiesChanged.
    const long errors_accepted = errors;
    if (c.vehicle_call("Kill") == 0) {
        pairs(n_diag, refused, pg_killed);
        c.vehicle_call("ClearKill");
    }
    std::printf("{\"calls\": %ld, \"settle_us\": %.0f, \"errors\": %ld, \"last_error\": \"%s\", "
                "\"setthrust_us\": %s, \"ping_us\": %s, "
                "\"back_to_back_setthrust_us\": %s, \"back_to_back_ping_us\": %s, "
                "\"refused_setthrust_us\": %s, \"ping_while_killed_us\": %s}\n",
                a.calls, a.settle_us, errors_accepted, errors_accepted ? last_error.c_str() : "",
                stats_json(st).c_str(), stats_json(pg).c_str(), stats_json(st_b2b).c_str(),
                stats_json(pg_b2b).c_str(), stats_json(refused).c_str(), stats_json(pg_killed).c_str());
    return 0;
}

// --- wire-log helpers ----------------------------------------------------------------------

struct Vehicle {
    uint32_t clock_hz = 100000;
    std::array<uint16_t, 8> addr7{};
    std::array<bool, 8> reversed{};
    uint8_t speed(size_t i, int32_t v) const { return motor_to_speed(reversed[i] ? -v : v).value_or(0x80); }
};

Vehicle describe(Client& c) {
    Vehicle v;
    v.clock_hz = c.get_trivial<uint32_t>(kSim, kSimPath, kSim, "ClockHz", 'u');
    for (size_t i = 0; i < 8; ++i) {
        const std::string p = std::string(kVehiclePath) + "/thruster/" + std::to_string(i);
        const uint8_t mt = c.get_trivial<uint8_t>(kVehicle, p.c_str(), "org.caracara.Vehicle1.Thruster", "Address", 'y');
        v.addr7[i] = static_cast<uint16_t>(mt >> 1);
        v.reversed[i] = c.get_trivial<int>(kVehicle, p.c_str(), "org.caracara.Vehicle1.Thruster", "Reversed", 'b') != 0;
    }
    return v;
}

bool is_order(const Entry& e) { return e.bus == "i2c" && !e.read && e.data.size() == 3 && e.result == "ack"; }
// A bus transaction, as opposed to the log's line events ("i2c-lines" recovery clocking,
// "gpio" line level changes).
bool is_transaction(const Entry& e) { return e.bus == "i2c" || e.bus == "spi"; }
bool is_zero_speed(uint8_t s) { return s == 0x80 || s == 0x7F; }

const char* kind_of(const Entry& e) {
    if (e.bus == "spi")
        return "spi";
    if (e.bus == "i2c")
        return e.read ? "status-read" : (e.data.size() == 3 ? "order" : "i2c-other");
    return "other";
}

// Polls the wire log from `since` into `log` until `done(log)` or the deadline.
template <typename Done>
bool poll_log(Client& c, uint64_t since, std::vector<Entry>& log, uint64_t deadline, Done done) {
    uint64_t next = since;
    for (;;) {
        next = c.wire_log(next, &log);
        if (done(log))
            return true;
        if (mono_ns() > deadline)
            return false;
        sleep_ns(1'000'000);
    }
}

struct Tally {
    std::map<std::string, long> inflight_kind; // what ended on the wire after t0, before the first new order
    std::map<std::string, long> preceding;     // how many such transactions: "0", "1", "2+"
    void add(const std::vector<Entry>& log, size_t first_new, uint64_t t0) {
        long n = 0;
        const Entry* first = nullptr;
        for (size_t k = 0; k < first_new; ++k)
            if (log[k].time_ns > t0 && is_transaction(log[k])) {
                ++n;
                if (!first)
                    first = &log[k];
            }
        preceding[n == 0 ? "0" : n == 1 ? "1" : "2+"]++;
        inflight_kind[first ? kind_of(*first) : "idle"]++;
    }
    std::string json() const {
        std::string s = "{\"preceding\": {";
        bool comma = false;
        for (auto& [k, v] : preceding) {
            s += (comma ? ", \"" : "\"") + k + "\": " + std::to_string(v);
            comma = true;
        }
        s += "}, \"inflight_kind\": {";
        comma = false;
        for (auto& [k, v] : inflight_kind) {
            s += (comma ? ", \"" : "\"") + k + "\": " + std::to_string(v);
            comma = true;
        }
        return s + "}}";
    }
};

// --- 2. command to wire --------------------------------------------------------------------

int cmd_cmd2wire(const Args& a) {
    Client c(a.bus);
    if (!c.wait_ready(10'000'000'000ull)) {
        std::fprintf(stderr, "caracara-bench: the vehicle is not ready\n");
        return 1;
    }
    const Vehicle veh = describe(c);
    const double bit_us = 1e6 / veh.clock_hz;
    Rng rng(a.seed);
    std::vector<double> last_us, first_us, reply_us, spacing_us, busy_last, idle_last, residual_us, burst_txns;
    Tally tally;
    long missing = 0;
    // Start from a known command.
    c.set_thrust(kSetB);
    sleep_ns(50'000'000);
    for (long s = 0; s < a.samples; ++s) {
        const Values& v = (s % 2 == 0) ? kSetA : kSetB;
        sleep_ns(static_cast<uint64_t>(rng.below(static_cast<uint64_t>(a.phase_ms * 1e6))));
        const uint64_t since = c.wire_next();
        const uint64_t t0 = mono_ns();
        std::string err;
        if (c.set_thrust(v, &err) < 0) {
            std::fprintf(stderr, "caracara-bench: SetThrust: %s\n", err.c_str());
            if (!c.wait_ready(5'000'000'000ull))
                return 1;
            continue;
        }
        const uint64_t t1 = mono_ns();
        sleep_ns(6'000'000); // let the burst go out before we ask the simulator anything
        std::vector<Entry> log;
        const uint8_t want_last = veh.speed(7, v[7]);
        auto found_last = [&](const std::vector<Entry>& l) {
            for (const Entry& e : l)
                if (is_order(e) && e.addr == veh.addr7[7] && e.data[0] == want_last && e.time_ns > t0)
                    return true;
            return false;
        };
        if (!poll_log(c, since, log, mono_ns() + 500'000'000ull, found_last)) {
            ++missing;
            continue;
        }
        size_t first_new = log.size(), last_new = log.size();
        for (size_t k = 0; k < log.size(); ++k) {
            const Entry& e = log[k];
            if (!is_order(e) || e.time_ns <= t0)
                continue;
            for (size_t i = 0; i < 8; ++i)
                if (e.addr == veh.addr7[i] && e.data[0] == veh.speed(i, v[i])) {
                    if (first_new == log.size())
                        first_new = k;
                    if (i == 7 && last_new == log.size())
                        last_new = k;
                }
        }
        const double lat = static_cast<double>(log[last_new].time_ns - t0) / 1000.0;
        last_us.push_back(lat);
        first_us.push_back(static_cast<double>(log[first_new].time_ns - t0) / 1000.0);
        reply_us.push_back(static_cast<double>(t1 - t0) / 1000.0);
        // Spacing between consecutive orders of the burst: wire time plus per-transaction overhead.
        if (last_new > first_new)
            spacing_us.push_back(static_cast<double>(log[last_new].time_ns - log[first_new].time_ns) / 1000.0 /
                                 static_cast<double>(last_new - first_new));
        tally.add(log, first_new, t0);
        // Transactions from the first new order to the last one: 8 when the burst went out
        // undisturbed; more when something (a tick, a status read) came in between.
        long between = 0;
        for (size_t k = first_new; k <= last_new; ++k)
            if (is_transaction(log[k]))
                ++between;
        burst_txns.push_back(static_cast<double>(between));
        if (std::getenv("CARACARA_BENCH_DEBUG") && lat > 5000) {
            std::fprintf(stderr, "sample %ld: %.0f us, t0=%llu\n", s, lat, static_cast<unsigned long long>(t0));
            for (const Entry& e : log)
                std::fprintf(stderr, "  %+9.1f us %-5s addr 0x%02x %s %s\n",
                             (static_cast<double>(e.time_ns) - static_cast<double>(t0)) / 1000.0, e.bus.c_str(), e.addr,
                             kind_of(e), e.data.empty() ? "" : std::to_string(e.data[0]).c_str());
        }
        bool busy = false;
        for (size_t k = 0; k < first_new; ++k)
            if (log[k].time_ns > t0 && is_transaction(log[k])) {
                busy = true;
                residual_us.push_back(static_cast<double>(log[k].time_ns - t0) / 1000.0);
                break;
            }
        (busy ? busy_last : idle_last).push_back(lat);
    }
    const double order_bits = 38; // START + 3 x 9-bit bytes + address byte + STOP
    std::printf("{\"samples\": %ld, \"missing\": %ld, \"clock_hz\": %u, \"order_wire_us\": %.3f, \"floor_us\": %.3f, "
                "\"last_us\": %s, \"first_us\": %s, \"reply_us\": %s, \"spacing_us\": %s, \"last_us_bus_idle\": %s, "
                "\"last_us_bus_busy\": %s, \"inflight_residual_us\": %s, \"burst_transactions\": %s, \"tally\": %s, "
                "\"raw\": {\"last_us\": %s, \"first_us\": %s, \"burst_transactions\": %s, \"busy_last_us\": %s, "
                "\"idle_last_us\": %s, \"inflight_residual_us\": %s, \"spacing_us\": %s}}\n",
                a.samples, missing, veh.clock_hz, order_bits * bit_us, 8 * order_bits * bit_us,
                stats_json(last_us).c_str(), stats_json(first_us).c_str(), stats_json(reply_us).c_str(),
                stats_json(spacing_us).c_str(), stats_json(idle_last).c_str(), stats_json(busy_last).c_str(),
                stats_json(residual_us).c_str(), stats_json(burst_txns).c_str(), tally.json().c_str(),
                array_json(last_us).c_str(), array_json(first_us).c_str(), array_json(burst_txns).c_str(),
                array_json(busy_last).c_str(), array_json(idle_last).c_str(), array_json(residual_us).c_str(),
                array_json(spacing_us).c_str());
    return 0;
}

// --- 3. kill to wire -----------------------------------------------------------------------

// The kill switch line as the simulator's wire log shows it ("gpio" entries): its offset and
// its level on the wire when engaged. None when the simulator does not say so (an older build).
struct SwitchLine {
    uint16_t offset = 0;
    uint8_t engaged_level = 1;
};

std::optional<SwitchLine> switch_line(Client& c) {
    uint32_t offset = 0;
    int active_low = 0;
    if (c.read_trivial(kSim, kSimPath, kSim, "KillSwitchLine", 'u', &offset) < 0 ||
        c.read_trivial(kSim, kSimPath, kSim, "KillSwitchActiveLow", 'b', &active_low) < 0)
        return std::nullopt;
    return SwitchLine{static_cast<uint16_t>(offset), static_cast<uint8_t>(active_low ? 0 : 1)};
}

int cmd_kill2wire(const Args& a) {
    const bool by_switch = a.source == "switch";
    Client c(a.bus);
    const Vehicle veh = describe(c);
    const double bit_us = 1e6 / veh.clock_hz;
    // With the switch, a sample starts at the kill switch edge: the simulator's "gpio" wire-log
    // entry of the switch line taking its engaged level, stamped when the line changed (when the
    // daemon's edge event can fire). The D-Bus hop of SetKillSwitch to the simulator is not the
    // daemon's; the figure from the client's clock before the call stays as a diagnostic
    // (edge_via_dbus_us), and the hop itself is dbus_to_edge_us.
    const std::optional<SwitchLine> line = by_switch ? switch_line(c) : std::nullopt;
    if (by_switch && !line)
        std::fprintf(stderr, "caracara-bench: the simulator does not name its kill switch line (KillSwitchLine): "
                             "timing from before SetKillSwitch\n");
    Rng rng(a.seed + 7);
    std::vector<double> all_us, first_us, call_us, via_dbus_us, hop_us;
    Tally tally;
    long missing = 0, missing_edge = 0, not_holding = 0, not_ready = 0;
    auto rearm = [&]() {
        if (by_switch)
            c.set_kill_switch(false);
        if (c.state() == "killed") {
            std::string e;
            if (c.vehicle_call("ClearKill", &e) < 0)
                std::fprintf(stderr, "caracara-bench: ClearKill: %s\n", e.c_str());
        }
        return c.wait_ready(5'000'000'000ull);
    };
    for (long s = 0; s < a.samples; ++s) {
        if (!rearm()) {
            ++not_ready;
            if (not_ready > 5) {
                std::fprintf(stderr, "caracara-bench: the vehicle does not become ready again\n");
                return 1;
            }
            continue;
        }
        // Drive all eight, and wait until the last one runs the new order.
        const Values& v = (s % 2 == 0) ? kSetA : kSetB;
        uint64_t since = c.wire_next();
        const uint64_t tc = mono_ns();
        if (c.set_thrust(v) < 0)
            continue;
        std::vector<Entry> pre;
        const uint8_t want_last = veh.speed(7, v[7]);
        poll_log(c, since, pre, mono_ns() + 500'000'000ull, [&](const std::vector<Entry>& l) {
            for (const Entry& e : l)
                if (is_order(e) && e.addr == veh.addr7[7] && e.data[0] == want_last && e.time_ns > tc)
                    return true;
            return false;
        });
        sleep_ns(static_cast<uint64_t>(rng.below(static_cast<uint64_t>(a.phase_ms * 1e6))));
        since = c.wire_next();
        const uint64_t t0 = mono_ns();
        if (by_switch) {
            if (c.set_kill_switch(true) < 0)
                return 1;
        } else {
            std::string e;
            if (c.vehicle_call("Kill", &e) < 0) {
                std::fprintf(stderr, "caracara-bench: Kill: %s\n", e.c_str());
                return 1;
            }
        }
        const uint64_t t1 = mono_ns();
        call_us.push_back(static_cast<double>(t1 - t0) / 1000.0);
        sleep_ns(8'000'000);
        std::vector<Entry> log;
        auto all_zero = [&](const std::vector<Entry>& l) {
            size_t seen = 0;
            for (size_t i = 0; i < 8; ++i)
                for (const Entry& e : l)
                    if (is_order(e) && e.addr == veh.addr7[i] && is_zero_speed(e.data[0]) && e.time_ns > t0) {
                        ++seen;
                        break;
                    }
            return seen == 8;
        };
        if (!poll_log(c, since, log, mono_ns() + 500'000'000ull, all_zero)) {
            ++missing;
            continue;
        }
        uint64_t start = t0;
        if (line) {
            const Entry* edge = nullptr;
            for (const Entry& e : log)
                if (e.bus == "gpio" && e.addr == line->offset && e.data.size() == 1 && e.data[0] == line->engaged_level) {
                    edge = &e;
                    break;
                }
            if (!edge) {
                ++missing_edge;
                continue;
            }
            start = edge->time_ns;
        }
        uint64_t worst = 0, first = UINT64_MAX;
        size_t first_zero = log.size();
        for (size_t i = 0; i < 8; ++i) {
            bool zeroed = false;
            for (size_t k = 0; k < log.size(); ++k) {
                const Entry& e = log[k];
                if (!is_order(e) || e.addr != veh.addr7[i] || e.time_ns <= start)
                    continue;
                if (!zeroed && is_zero_speed(e.data[0])) {
                    zeroed = true;
                    worst = std::max(worst, e.time_ns);
                    first = std::min(first, e.time_ns);
                    first_zero = std::min(first_zero, k);
                } else if (zeroed && !is_zero_speed(e.data[0])) {
                    ++not_holding; // a non-zero order after the zero one: the kill did not hold
                }
            }
        }
        all_us.push_back(static_cast<double>(worst - start) / 1000.0);
        first_us.push_back(static_cast<double>(first - start) / 1000.0);
        if (line) {
            via_dbus_us.push_back(static_cast<double>(worst - t0) / 1000.0);
            hop_us.push_back(static_cast<double>(start - t0) / 1000.0);
        }
        tally.add(log, first_zero, start);
    }
    rearm();
    c.set_thrust({0, 0, 0, 0, 0, 0, 0, 0});
    const double order_bits = 38;
    // "start": where the samples start, "edge" (the simulator's kill switch edge) or "call"
    // (the client's clock before Kill() or SetKillSwitch).
    std::string edge_stats, edge_raw;
    if (line) {
        edge_stats = ", \"edge_via_dbus_us\": " + stats_json(via_dbus_us) + ", \"dbus_to_edge_us\": " + stats_json(hop_us);
        edge_raw = ", \"edge_via_dbus_us\": " + array_json(via_dbus_us) + ", \"dbus_to_edge_us\": " + array_json(hop_us);
    }
    std::printf("{\"source\": \"%s\", \"start\": \"%s\", \"samples\": %ld, \"missing\": %ld, \"missing_edge\": %ld, "
                "\"not_holding\": %ld, \"clock_hz\": %u, \"floor_us\": %.3f, \"all_zero_us\": %s, \"first_zero_us\": %s, "
                "\"call_us\": %s%s, \"tally\": %s, \"raw\": {\"all_zero_us\": %s, \"first_zero_us\": %s, \"call_us\": %s%s}}\n",
                a.source.c_str(), line ? "edge" : "call", a.samples, missing, missing_edge, not_holding, veh.clock_hz,
                8 * order_bits * bit_us, stats_json(all_us).c_str(), stats_json(first_us).c_str(),
                stats_json(call_us).c_str(), edge_stats.c_str(), tally.json().c_str(), array_json(all_us).c_str(),
                array_json(first_us).c_str(), array_json(call_us).c_str(), edge_raw.c_str());
    return 0;
}

// --- 6. a kill to the kill output (the run enable), healthy or with a hung thruster -------------

// From Kill() (the client's clock before the call) or the kill switch edge (its wire-log stamp)
// to the kill output's edge in the wire log: the one GPIO write that de-energizes the thrusters,
// which must not wait behind a transfer on the wire. The zero orders are not waited for (a hung
// thruster's never completes).
int cmd_kill2output(const Args& a) {
    const bool by_switch = a.source == "switch";
    Client c(a.bus);
    uint32_t out_line = 0;
    if (c.read_trivial(kSim, kSimPath, kSim, "KillOutputLine", 'u', &out_line) < 0) {
        std::fprintf(stderr, "caracara-bench: the simulator does not name its kill output line\n");
        return 1;
    }
    const std::optional<SwitchLine> line = by_switch ? switch_line(c) : std::nullopt;
    if (by_switch && !line) {
        std::fprintf(stderr, "caracara-bench: the simulator does not name its kill switch line\n");
        return 1;
    }
    Rng rng(a.seed + 11);
    std::vector<double> us;
    long missing = 0;
    for (long s = 0; s < a.samples; ++s) {
        if (by_switch)
            c.set_kill_switch(false);
        if (a.floor) {
            // No vehicle: the floor program only follows the switch with the output.
            sleep_ns(2'000'000);
        } else {
            if (c.state() == "killed")
                c.vehicle_call("ClearKill");
            if (!c.wait_ready(5'000'000'000ull)) {
                std::fprintf(stderr, "caracara-bench: the vehicle does not become ready again\n");
                return 1;
            }
            c.set_thrust((s % 2 == 0) ? kSetA : kSetB);
        }
        sleep_ns(static_cast<uint64_t>(rng.below(static_cast<uint64_t>(a.phase_ms * 1e6))));
        const uint64_t since = c.wire_next();
        const uint64_t t0 = mono_ns();
        if (by_switch ? c.set_kill_switch(true) < 0 : c.vehicle_call("Kill") < 0)
            return 1;
        std::vector<Entry> log;
        const Entry* out = nullptr;
        const Entry* edge = nullptr;
        poll_log(c, since, log, mono_ns() + 3'000'000'000ull, [&](const std::vector<Entry>& l) {
            out = edge = nullptr;
            for (const Entry& e : l) {
                if (e.bus != "gpio")
                    continue;
                if (line && !edge && e.addr == line->offset)
                    edge = &e;
                if (!out && e.addr == out_line)
                    out = &e;
            }
            return out && (!line || edge);
        });
        if (!out || (line && !edge)) {
            ++missing;
            continue;
        }
        const uint64_t start = line ? edge->time_ns : t0;
        us.push_back(out->time_ns > start ? static_cast<double>(out->time_ns - start) / 1000.0 : 0.0);
    }
    if (by_switch)
        c.set_kill_switch(false);
    std::printf("{\"source\": \"%s\", \"samples\": %ld, \"missing\": %ld, \"kill_output_us\": %s, "
                "\"raw\": {\"kill_output_us\": %s}}\n",
                a.source.c_str(), a.samples, missing, stats_json(us).c_str(), array_json(us).c_str());
    return 0;
}

// --- 4. loop rate, and a command stream for the cost figures ---------------------------------

int cmd_cycles(const Args& a) {
    Client c(a.bus);
    const uint64_t c0 = c.cycles();
    const uint64_t t0 = mono_ns();
    sleep_ns(static_cast<uint64_t>(a.seconds * 1e9));
    const uint64_t c1 = c.cycles();
    const uint64_t t1 = mono_ns();
    const double secs = static_cast<double>(t1 - t0) / 1e9;
    std::printf("{\"cycles\": %llu, \"seconds\": %.6f, \"rate_hz\": %.3f, \"start\": %llu}\n",
                static_cast<unsigned long long>(c1 - c0), secs, static_cast<double>(c1 - c0) / secs,
                static_cast<unsigned long long>(c0));
    return 0;
}

int cmd_stream(const Args& a) {
    Client c(a.bus);
    const uint64_t period = static_cast<uint64_t>(1e9 / a.hz);
    const uint64_t start = mono_ns();
    const uint64_t end = start + static_cast<uint64_t>(a.seconds * 1e9);
    uint64_t next = start;
    long calls = 0, errors = 0;
    std::string last_error;
    while (mono_ns() < end) {
        if (c.set_thrust(calls % 2 ? kSetA : kSetB, &last_error) < 0)
            ++errors;
        ++calls;
        next += period;
        sleep_until_ns(next);
    }
    std::printf("{\"calls\": %ld, \"errors\": %ld, \"last_error\": \"%s\"}\n", calls, errors,
                errors ? last_error.c_str() : "");
    return 0;
}

int cmd_wait_ready(const Args& a) {
    Client c(a.bus);
    if (!c.wait_ready(static_cast<uint64_t>(a.timeout_ms * 1e6))) {
        std::fprintf(stderr, "caracara-bench: not ready after %.0f ms (state '%s')\n", a.timeout_ms, c.state().c_str());
        return 1;
    }
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    const Args a = parse(argc, argv);
    if (a.command == "rtt") return cmd_rtt(a);
    if (a.command == "cmd2wire") return cmd_cmd2wire(a);
    if (a.command == "kill2wire") return cmd_kill2wire(a);
    if (a.command == "kill2output") return cmd_kill2output(a);
    if (a.command == "cycles") return cmd_cycles(a);
    if (a.command == "stream") return cmd_stream(a);
    if (a.command == "wait-ready") return cmd_wait_ready(a);
    std::fprintf(stderr, "caracara-bench: unknown command %s\n", a.command.c_str());
    return 2;
}
