// Integration-test fixture: a private dbus-daemon and a real caracara-sim process, plus
// small sd-bus helpers to read the simulator's inspection API. Nothing here is mocked.
#pragma once

#include "drivers/sdbus/sdbus.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <sys/types.h>
#include <vector>

namespace caracara::test {

class Process {
public:
    Process() = default;
    Process(const Process&) = delete;
    Process& operator=(const Process&) = delete;
    ~Process() { stop(); }
    // Starts command[0] (found in PATH if it has no slash) with the given arguments, a built
    // program through the cross build's emulator; stdout/stderr go to `log_path`.
    void start(const std::vector<std::string>& command, const std::string& log_path);
    void stop(int sig = 15);    // signal, then wait
    // SIGTERM and wait: the exit status (128 + signal if killed by one), -1 if not running.
    // A sanitizer report in the child shows up here as a non-zero status.
    int terminate();
    int wait_exit(int timeout_ms); // exit status, or -1 if still running
    bool running();
    pid_t pid() const { return pid_; }

private:
    pid_t pid_ = -1;
};

struct WireEntry {
    uint64_t index, time_ns, transaction;
    std::string bus;
    uint16_t addr;
    bool read;
    std::vector<uint8_t> data, miso;
    std::string result;
};

class SimFixture {
public:
    // Starts a private bus and caracara-sim with `sim_args` appended (e.g. --config FILE).
    explicit SimFixture(const std::vector<std::string>& sim_args = {});
    ~SimFixture();

    const std::string& dir() const { return dir_; }
    const std::string& socket() const { return socket_; }
    std::string bus_address() const { return "unix:path=" + dir_ + "/bus"; }
    sd_bus* bus() { return bus_.get(); }
    std::string write_file(const std::string& name, const std::string& text);

    // Inspection API helpers (throw std::runtime_error on D-Bus errors).
    std::string thruster_path(unsigned i) const { return "/org/caracara/Simulator1/thruster/" + std::to_string(i); }
    uint8_t thruster_byte(unsigned i, const char* prop);
    uint64_t thruster_u64(unsigned i, const char* prop);
    double thruster_double(unsigned i, const char* prop);
    std::vector<uint8_t> thruster_bytes(unsigned i, const char* prop);
    std::vector<std::string> thruster_strings(unsigned i, const char* prop);
    // Calls a method; returns the D-Bus error name, or "" on success.
    std::string call(const std::string& path, const char* iface, const char* method, const char* sig, ...);
    std::vector<WireEntry> wire_log(uint64_t since = 0);
    // GetWireLogPage(since, max_entries); `next` gets the index to read on from.
    std::vector<WireEntry> wire_log_page(uint64_t since, uint32_t max_entries, uint64_t* next);
    // Root object (org.caracara.Simulator1) properties.
    bool root_bool(const char* prop);
    uint64_t root_u64(const char* prop);
    uint32_t root_u32(const char* prop);
    std::string root_string(const char* prop);

    Process sim;
    Process dbus_daemon;

private:
    static std::vector<WireEntry> read_wire_log(sd_bus_message* reply, uint64_t* next);

    std::string dir_;
    std::string socket_;
    dbus::BusPtr bus_;
};

// Directory of the built binaries, set by CMake.
std::string bin(const char* name);

// The whole file; "" when it cannot be read.
std::string read_file(const std::string& path);

// Starts a private dbus-daemon listening on DIR/NAME (config DIR/NAME.conf, log DIR/NAME-dbus.log)
// and waits until it listens; returns its address.
std::string start_private_bus(Process& daemon, const std::string& dir, const std::string& name);

} // namespace caracara::test
