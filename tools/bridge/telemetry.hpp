// The bridge's one reading connection to caracarad: the vehicle's objects (GetManagedObjects),
// kept current by PropertiesChanged and turned into the Foxglove channels' messages
// (tools/bridge/channel_message_builder.hpp) as they change, which is at the daemon's telemetry
// rate for the telemetry properties. Kills, faults, bus losses and recoveries, arming and failsafes
// become foxglove.Log messages on /events. Reading needs no privilege; commands go through each
// client's own connection (tools/bridge/command_link.hpp).
#pragma once

#include "tools/bridge/bus_watch.hpp"
#include "tools/bridge/channel_message_builder.hpp"
#include "tools/client/client.hpp"
#include "tools/client/object_mirror.hpp"

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace caracara::bridge {

using Payload = std::shared_ptr<const std::string>;

class Telemetry {
public:
    // publish(channel position in foxglove::channels(), time in ns since the epoch, JSON).
    using Publish = std::function<void(std::size_t, uint64_t, const Payload&)>;

    Telemetry(boost::asio::io_context& io, caracara::dbus::BusChoice bus, Publish publish);
    ~Telemetry();

    // Connects and loads the objects; retries every second while caracarad is not there.
    void start();
    // The last message of a channel (null before the first), for a new subscriber.
    Payload latest(std::size_t channel) const { return channel < latest_.size() ? latest_[channel] : nullptr; }

private:
    static int on_vehicle_signal(sd_bus_message* m, void* userdata, sd_bus_error* error);
    static int on_controller_pid(sd_bus_message* m, void* userdata, sd_bus_error* error);
    // The controller in words: its process, asked of the bus daemon (controller_name in the state).
    void name_controller(const std::string& unique_name);
    void reload();
    void loaded(); // after the objects were (re)loaded
    bool connect();
    void retry();
    void changed(const std::string& path, const std::string& iface, const client::Props& changes,
                 const client::Props& before);
    void mark(std::size_t channel);
    void flush();
    void log(int level, const std::string& name, const std::string& message);
    const client::Props& props(const std::string& path, const char* iface) const { return mirror_.props(path, iface); }

    boost::asio::io_context& io_;
    caracara::dbus::BusChoice choice_;
    Publish publish_;
    std::unique_ptr<client::Client> client_;
    std::vector<caracara::dbus::SlotPtr> slots_;
    std::unique_ptr<BusWatch> watch_;
    boost::asio::steady_timer retry_;
    client::ObjectMirror mirror_;
    std::set<std::size_t> dirty_;
    bool flush_posted_ = false;
    ChannelMessageBuilder messages_{mirror_};
    std::vector<Payload> latest_;
    caracara::dbus::SlotPtr controller_slot_;
    std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

} // namespace caracara::bridge
