#include "tools/bridge/telemetry.hpp"

#include "tools/foxglove/channels.hpp"

#include <boost/asio/post.hpp>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <unistd.h>

namespace caracara::bridge {

namespace fg = caracara::foxglove;
using client::property;
using client::Props;
using client::Value;
using fg::ChannelKind;

namespace {

const std::string kRoot = caracara::dbus::kRootPath;
const std::string kThrusterPrefix = kRoot + "/thruster/";

uint64_t now_ns() {
    timespec t{};
    clock_gettime(CLOCK_REALTIME, &t);
    return static_cast<uint64_t>(t.tv_sec) * 1'000'000'000u + static_cast<uint64_t>(t.tv_nsec);
}

// The thruster number of an object path, or -1.
int thruster_of(const std::string& path) {
    if (!path.starts_with(kThrusterPrefix))
        return -1;
    const std::string n = path.substr(kThrusterPrefix.size());
    if (n.size() != 1 || n[0] < '0' || n[0] >= '0' + static_cast<int>(fg::kThrusters))
        return -1;
    return n[0] - '0';
}

// A process's name as the kernel has it (/proc/PID/comm), "" when gone.
std::string process_name(uint32_t pid) {
    char path[48];
    std::snprintf(path, sizeof path, "/proc/%u/comm", pid);
    std::FILE* f = std::fopen(path, "re");
    if (!f)
        return "";
    char name[64] = {};
    const bool ok = std::fgets(name, sizeof name, f) != nullptr;
    std::fclose(f);
    std::string out = ok ? name : "";
    while (!out.empty() && (out.back() == '\n' || out.back() == ' '))
        out.pop_back();
    return out;
}

} // namespace

Telemetry::Telemetry(boost::asio::io_context& io, caracara::dbus::BusChoice bus, Publish publish)
    : io_(io), choice_(std::move(bus)), publish_(std::move(publish)), retry_(io),
      mirror_([this](const std::string& path, const std::string& iface, const Props& changes,
                     const Props& before) { changed(path, iface, changes, before); },
              [this] {
                  // A restarted caracarad: its objects are loaded again (the old values are gone),
                  // not from inside this connection's processing: the call waits for its reply.
                  boost::asio::post(io_, [this, alive = alive_] {
                      if (*alive)
                          reload();
                  });
              }),
      latest_(fg::channels().size()) {}

Telemetry::~Telemetry() {
    *alive_ = false;
    watch_.reset();
    slots_.clear();
    mirror_.clear();
    controller_slot_.reset();
}

void Telemetry::loaded() {
    const Props& root = props(kRoot, caracara::dbus::kVehicleIface);
    messages_.follow_surfacing(root, now_ns());
    name_controller(property(root, "Controller").s);
}

void Telemetry::start() {
    if (!connect())
        retry();
}

void Telemetry::retry() {
    retry_.expires_after(std::chrono::seconds(1));
    retry_.async_wait([this, alive = alive_](boost::system::error_code ec) {
        if (!ec && *alive)
            start();
    });
}

bool Telemetry::connect() {
    watch_.reset();
    slots_.clear();
    mirror_.clear();
    controller_slot_.reset();
    client_ = std::make_unique<client::Client>(choice_);
    try {
        sd_bus* bus = client_->bus();
        sd_bus_slot* slot = nullptr;
        for (const char* member : {"BusLost", "BusRestored"}) {
            if (sd_bus_match_signal(bus, &slot, caracara::dbus::kBusName, caracara::dbus::kBusPath,
                                    caracara::dbus::kBusIface, member, on_vehicle_signal, this) < 0)
                return false;
            slots_.emplace_back(slot);
        }
        // Failsafe(s condition, s action, i thruster) on the vehicle, where the daemon has it.
        if (sd_bus_match_signal(bus, &slot, caracara::dbus::kBusName, caracara::dbus::kRootPath,
                                caracara::dbus::kVehicleIface, "Failsafe", on_vehicle_signal, this) < 0)
            return false;
        slots_.emplace_back(slot);
        // Subscribed before loading, so no change falls between the two.
        if (!mirror_.subscribe_and_load(*client_))
            return false;
    } catch (const client::Failure& f) {
        std::fprintf(stderr, "caracara-bridge: caracarad not reachable (%s); retrying\n", f.message.c_str());
        slots_.clear();
        mirror_.clear();
        return false;
    }
    watch_ = std::make_unique<BusWatch>(io_, client_->bus(), [this] {
        std::fprintf(stderr, "caracara-bridge: the bus connection closed; reconnecting\n");
        boost::asio::post(io_, [this, alive = alive_] {
            if (*alive)
                retry();
        });
    });
    loaded();
    for (std::size_t i = 0; i < fg::channels().size(); ++i)
        if (fg::channels()[i].kind != ChannelKind::Events)
            mark(i);
    return true;
}

int Telemetry::on_vehicle_signal(sd_bus_message* m, void* userdata, sd_bus_error*) {
    auto* self = static_cast<Telemetry*>(userdata);
    const std::string member = sd_bus_message_get_member(m) ? sd_bus_message_get_member(m) : "";
    if (member == "BusLost") {
        const char* reason = nullptr;
        if (sd_bus_message_read(m, "s", &reason) >= 0)
            self->log(4, "bus", std::string("I2C bus lost: ") + (reason ? reason : ""));
    } else if (member == "BusRestored") {
        uint32_t pulses = 0;
        double ms = 0;
        if (sd_bus_message_read(m, "ud", &pulses, &ms) >= 0) {
            char text[96];
            std::snprintf(text, sizeof text, "I2C bus restored after %u SCL pulses in %.1f ms", pulses, ms);
            self->log(2, "bus", text);
        }
    } else if (member == "Failsafe") {
        const char* condition = nullptr;
        const char* action = nullptr;
        int32_t thruster = -1;
        if (sd_bus_message_read(m, "ssi", &condition, &action, &thruster) >= 0)
            self->log(3, "failsafe",
                      std::string(condition ? condition : "") + " -> " + (action ? action : "") +
                          (thruster >= 0 ? " (thruster " + std::to_string(thruster) + ")" : ""));
    }
    return 0;
}

void Telemetry::reload() {
    if (!watch_ || !client_)
        return; // reconnecting: connect() loads the objects
    try {
        mirror_.load(*client_);
    } catch (const client::Failure& f) {
        std::fprintf(stderr, "caracara-bridge: reloading caracarad's objects failed (%s)\n", f.message.c_str());
        return;
    }
    loaded();
    for (std::size_t i = 0; i < fg::channels().size(); ++i)
        if (fg::channels()[i].kind != ChannelKind::Events)
            mark(i);
    watch_->kick();
}

void Telemetry::changed(const std::string& path, const std::string& iface, const Props& changes, const Props& before) {
    const Props& stored = mirror_.props(path, iface.c_str());
    if (path == kRoot) {
        bool state = false, motors = false;
        for (const auto& [name, _] : changes)
            (name == "MotorValues" || name == "RequestedValues" ? motors : state) = true;
        if (motors)
            mark(fg::channel_position(ChannelKind::Motors));
        if (state)
            mark(fg::channel_position(ChannelKind::VehicleState));
        messages_.follow_surfacing(stored, now_ns());
        if (changes.contains("Controller"))
            name_controller(property(stored, "Controller").s);
        if (changes.contains("State") && property(before, "State").s != property(stored, "State").s) {
            const std::string s = property(stored, "State").s;
            const std::string source = property(stored, "KillSource").s;
            const int level = s == "killed" || s == "powered-off" ? 3 : s == "fault" ? 4 : 2;
            log(level, s == "killed" ? "kill" : s == "arming" ? "arming" : "state",
                s + (source.empty() ? "" : " (" + source + ")"));
        }
        if (changes.contains("Profile") && property(before, "Profile").s != property(stored, "Profile").s)
            log(2, "profile", "profile " + property(stored, "Profile").s);
    } else if (const int t = thruster_of(path); t >= 0) {
        mark(fg::channel_position(ChannelKind::Thruster, static_cast<unsigned>(t)));
        if (changes.contains("Faults")) {
            std::string list;
            for (const Value& f : property(stored, "Faults").items)
                list += (list.empty() ? "" : ",") + f.s;
            std::string old;
            for (const Value& f : property(before, "Faults").items)
                old += (old.empty() ? "" : ",") + f.s;
            if (list != old)
                log(list.empty() ? 2 : 4, "fault", "thruster " + std::to_string(t) + " faults: " + (list.empty() ? "none" : list));
        }
    } else if (path == caracara::dbus::kTeensyPath) {
        mark(fg::channel_position(ChannelKind::Teensy));
        if (changes.contains("Orientation"))
            mark(fg::channel_position(ChannelKind::Attitude));
    } else if (path == caracara::dbus::kBusPath) {
        mark(fg::channel_position(ChannelKind::I2cBus));
        if (changes.contains("Recoveries") && property(before, "Recoveries").unsigned_integer() !=
                                                   property(stored, "Recoveries").unsigned_integer())
            log(2, "recovery", "I2C bus recoveries: " + std::to_string(property(stored, "Recoveries").unsigned_integer()));
    }
}

void Telemetry::name_controller(const std::string& unique_name) {
    messages_.controller_changed(unique_name);
    controller_slot_.reset();
    if (unique_name.empty() || !client_)
        return;
    // Asked of the bus daemon without waiting: this thread also carries the kills.
    sd_bus_slot* slot = nullptr;
    if (sd_bus_call_method_async(client_->bus(), &slot, "org.freedesktop.DBus", "/org/freedesktop/DBus",
                                 "org.freedesktop.DBus", "GetConnectionUnixProcessID", on_controller_pid, this, "s",
                                 unique_name.c_str()) >= 0)
        controller_slot_.reset(slot);
    if (watch_)
        watch_->kick();
}

int Telemetry::on_controller_pid(sd_bus_message* m, void* userdata, sd_bus_error*) {
    auto* self = static_cast<Telemetry*>(userdata);
    uint32_t pid = 0;
    if (sd_bus_message_is_method_error(m, nullptr) || sd_bus_message_read(m, "u", &pid) < 0 || pid == 0)
        return 0;
    const std::string name = process_name(pid);
    // Each browser tab or Foxglove client of this bridge commands through a connection of its own.
    self->messages_.describe_controller(pid == static_cast<uint32_t>(getpid())
                                            ? "a cockpit or Foxglove client of this bridge"
                                        : name.empty() ? "process " + std::to_string(pid)
                                                       : name + " (pid " + std::to_string(pid) + ")");
    self->mark(fg::channel_position(ChannelKind::VehicleState));
    return 0;
}

void Telemetry::log(int level, const std::string& name, const std::string& message) {
    const uint64_t now = now_ns();
    fg::LogEvent e{now, static_cast<fg::LogLevel>(level), name, message};
    const std::size_t pos = fg::channel_position(ChannelKind::Events);
    latest_[pos] = std::make_shared<const std::string>(fg::to_json(e));
    publish_(pos, now, latest_[pos]);
}

void Telemetry::mark(std::size_t channel) {
    dirty_.insert(channel);
    // One message per channel for all the changes one batch of signals brings.
    if (!flush_posted_) {
        flush_posted_ = true;
        boost::asio::post(io_, [this, alive = alive_] {
            if (*alive)
                flush();
        });
    }
}

void Telemetry::flush() {
    flush_posted_ = false;
    const uint64_t now = now_ns();
    const std::set<std::size_t> dirty = std::move(dirty_);
    dirty_.clear();
    for (const std::size_t c : dirty) {
        std::optional<std::string> json = messages_.build(c, now);
        if (!json)
            continue;
        latest_[c] = std::make_shared<const std::string>(std::move(*json));
        publish_(c, now, latest_[c]);
    }
}

} // namespace caracara::bridge
