// caracarad's objects as a reading client holds them: loaded with GetManagedObjects, kept current
// by PropertiesChanged, loaded again when caracarad restarts (a new owner of its name). The
// topside clients that turn the vehicle's properties into messages (caracara-bridge's
// Telemetry, caracara-ros's TelemetryPublisher) each hold one.
#pragma once

#include "tools/client/client.hpp"

#include <functional>
#include <string>
#include <vector>

namespace caracara::client {

class ObjectMirror {
public:
    // `changed(path, iface, changes, before)`: after the stored properties took the changes;
    // `before`: that interface's properties as they were.
    // `restarted()`: caracarad has a new owner; the caller calls load() where it may wait.
    using Changed = std::function<void(const std::string&, const std::string&, const Props&, const Props&)>;
    ObjectMirror(Changed changed, std::function<void()> restarted)
        : changed_(std::move(changed)), restarted_(std::move(restarted)) {}

    // Subscribes (before loading, so no change falls between the two), then loads. Throws
    // Failure; false when a subscription failed.
    bool subscribe_and_load(Client& client);
    void load(Client& client) { objects_ = client.get_objects(); }
    void clear() { slots_.clear(); }
    // An object's properties on one interface (empty when caracarad has none).
    const Props& props(const std::string& path, const char* iface) const;

private:
    static int on_properties_changed(sd_bus_message* m, void* userdata, sd_bus_error* error);
    static int on_owner_changed(sd_bus_message* m, void* userdata, sd_bus_error* error);

    Changed changed_;
    std::function<void()> restarted_;
    std::vector<caracara::dbus::SlotPtr> slots_;
    Objects objects_;
};

} // namespace caracara::client
