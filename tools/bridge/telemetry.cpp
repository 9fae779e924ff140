#include "tools/bridge/telemetry.hpp"

#include "drivers/protocol/seabotix.hpp"
#include "tools/bridge/failsafe_state.hpp"
#include "tools/foxglove/channels.hpp"

#include <boost/asio/post.hpp>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <unistd.h>

namespace caracara::bridge {

namespace fg = caracara::foxglove;
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

const Value kNone;

const Value& get(const Props& p, const char* name) {
    const auto it = p.find(name);
    return it == p.end() ? kNone : it->second;
}

std::string text(const Props& p, const char* name) { return get(p, name).s; }

std::vector<int64_t> integers(const Value& v) {
    std::vector<int64_t> out;
    for (const Value& item : v.items)
        out.push_back(item.integer());
    return out;
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
    follow_surfacing(root);
    name_controller(text(root, "Controller"));
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
        follow_surfacing(stored);
        if (changes.contains("Controller"))
            name_controller(text(stored, "Controller"));
        if (changes.contains("State") && text(before, "State") != text(stored, "State")) {
            const std::string s = text(stored, "State");
            const std::string source = text(stored, "KillSource");
            const int level = s == "killed" || s == "powered-off" ? 3 : s == "fault" ? 4 : 2;
            log(level, s == "killed" ? "kill" : s == "arming" ? "arming" : "state",
                s + (source.empty() ? "" : " (" + source + ")"));
        }
        if (changes.contains("Profile") && text(before, "Profile") != text(stored, "Profile"))
            log(2, "profile", "profile " + text(stored, "Profile"));
    } else if (const int t = thruster_of(path); t >= 0) {
        mark(fg::channel_position(ChannelKind::Thruster, static_cast<unsigned>(t)));
        if (changes.contains("Faults")) {
            std::string list;
            for (const Value& f : get(stored, "Faults").items)
                list += (list.empty() ? "" : ",") + f.s;
            std::string old;
            for (const Value& f : get(before, "Faults").items)
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
        if (changes.contains("Recoveries") && get(before, "Recoveries").unsigned_integer() !=
                                                   get(stored, "Recoveries").unsigned_integer())
            log(2, "recovery", "I2C bus recoveries: " + std::to_string(get(stored, "Recoveries").unsigned_integer()));
    }
}

void Telemetry::follow_surfacing(const Props& root) {
    const std::string state = text(root, "State");
    bool surfacing = false;
    if (state != "killed" && state != "powered-off")
        for (const fg::ActiveFailsafe& f : failsafes(root))
            surfacing = surfacing || f.action == "surface";
    if (!surfacing)
        surfacing_since_ = 0;
    else if (!surfacing_since_)
        surfacing_since_ = now_ns();
}

void Telemetry::name_controller(const std::string& unique_name) {
    controller_ = {unique_name, ""};
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
    self->controller_.words = pid == static_cast<uint32_t>(getpid()) ? "a cockpit or Foxglove client of this bridge"
                              : name.empty()                          ? "process " + std::to_string(pid)
                                                                      : name + " (pid " + std::to_string(pid) + ")";
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
    for (const std::size_t c : dirty)
        build(c, now);
}

void Telemetry::build(std::size_t channel, uint64_t now) {
    const fg::ChannelInfo& info = fg::channels()[channel];
    std::string json;
    switch (info.kind) {
    case ChannelKind::VehicleState: {
        const Props& p = props(kRoot, caracara::dbus::kVehicleIface);
        const std::string controller = text(p, "Controller");
        fg::VehicleState s{text(p, "State"), text(p, "KillSource"), text(p, "Profile"),
                           get(p, "ProfileFactor").number(), get(p, "BudgetLimit").integer(),
                           get(p, "Saturated").boolean(), get(p, "CommandAgeMs").integer(), controller,
                           controller == controller_.unique_name ? controller_.words : "", {}, failsafes(p),
                           surfacing_since_ ? static_cast<int64_t>((now - surfacing_since_) / 1'000'000u) : -1};
        const Value& leds = get(p, "Leds");
        for (std::size_t i = 0; i < 3 && i < leds.items.size(); ++i)
            s.leds[i] = leds.items[i].integer();
        add_time_left(p, s);
        if (const Value& test = get(p, "MotorTest"); test.items.size() == 2) {
            s.motor_test_thruster = test.items[0].integer();
            s.motor_test_value = test.items[1].integer();
        }
        s.motor_test_limit = get(p, "MotorTestLimit").integer();
        json = fg::to_json(s);
        break;
    }
    case ChannelKind::Motors: {
        const Props& p = props(kRoot, caracara::dbus::kVehicleIface);
        fg::Motors m;
        const auto applied = integers(get(p, "MotorValues")), requested = integers(get(p, "RequestedValues"));
        for (std::size_t i = 0; i < fg::kThrusters; ++i) {
            m.applied[i] = i < applied.size() ? applied[i] : 0;
            m.requested[i] = i < requested.size() ? requested[i] : 0;
        }
        json = fg::to_json(m);
        break;
    }
    case ChannelKind::Thruster: {
        const Props& p = props(kThrusterPrefix + std::to_string(info.index), caracara::dbus::kThrusterIface);
        fg::Thruster t;
        t.index = info.index;
        t.reachable = get(p, "Online").boolean();
        const auto speed = caracara::speed_to_motor(static_cast<uint8_t>(get(p, "ActualSpeed").unsigned_integer()));
        t.speed = speed ? *speed : 0;
        t.ordered_value = get(p, "OrderedValue").integer();
        t.current = get(p, "Current").number();
        t.temperature = get(p, "Temperature").number();
        for (const Value& f : get(p, "Faults").items) {
            t.faults.push_back(f.s);
            for (const auto fault : caracara::kAllFaults)
                if (caracara::fault_name(fault) == f.s)
                    t.fault_bits |= 1u << static_cast<unsigned>(fault);
        }
        json = fg::to_json(t);
        break;
    }
    case ChannelKind::Teensy:
    case ChannelKind::Attitude: {
        const Props& p = props(caracara::dbus::kTeensyPath, caracara::dbus::kTeensyIface);
        fg::Teensy t;
        const Value& o = get(p, "Orientation");
        if (o.items.size() == 3) {
            t.yaw = o.items[0].number();
            t.pitch = o.items[1].number();
            t.roll = o.items[2].number();
        }
        if (info.kind == ChannelKind::Attitude) {
            json = fg::attitude_json(now, t.yaw, t.pitch, t.roll);
            break;
        }
        t.online = get(p, "Online").boolean();
        t.distances = integers(get(p, "Distances"));
        t.servos = integers(get(p, "Servos"));
        t.task = text(p, "Task");
        t.frames = get(p, "Frames").unsigned_integer();
        t.busy_retries = get(p, "BusyRetries").unsigned_integer();
        t.link_errors = get(p, "LinkErrors").unsigned_integer();
        json = fg::to_json(t);
        break;
    }
    case ChannelKind::I2cBus: {
        const Props& p = props(caracara::dbus::kBusPath, caracara::dbus::kBusIface);
        fg::I2cBus b{text(p, "State"), get(p, "Transactions").unsigned_integer(), get(p, "Errors").unsigned_integer(),
                     get(p, "Recoveries").unsigned_integer(), get(p, "RecoveryFailures").unsigned_integer(),
                     text(p, "LastError")};
        json = fg::to_json(b);
        break;
    }
    case ChannelKind::Events:
        return;
    }
    latest_[channel] = std::make_shared<const std::string>(std::move(json));
    publish_(channel, now, latest_[channel]);
}

} // namespace caracara::bridge
