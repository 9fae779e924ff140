#include "tools/client/object_mirror.hpp"

#include <string_view>

namespace caracara::client {

bool ObjectMirror::subscribe_and_load(Client& client) {
    slots_.clear();
    sd_bus* bus = client.bus();
    sd_bus_slot* slot = nullptr;
    if (sd_bus_match_signal(bus, &slot, caracara::dbus::kBusName, nullptr, "org.freedesktop.DBus.Properties",
                            "PropertiesChanged", on_properties_changed, this) < 0)
        return false;
    slots_.emplace_back(slot);
    if (sd_bus_match_signal(bus, &slot, "org.freedesktop.DBus", "/org/freedesktop/DBus", "org.freedesktop.DBus",
                            "NameOwnerChanged", on_owner_changed, this) < 0)
        return false;
    slots_.emplace_back(slot);
    load(client);
    return true;
}

const Props& ObjectMirror::props(const std::string& path, const char* iface) const {
    static const Props none;
    const auto o = objects_.find(path);
    if (o == objects_.end())
        return none;
    const auto i = o->second.find(iface);
    return i == o->second.end() ? none : i->second;
}

int ObjectMirror::on_properties_changed(sd_bus_message* m, void* userdata, sd_bus_error*) {
    auto* self = static_cast<ObjectMirror*>(userdata);
    try {
        const char* iface = nullptr;
        if (sd_bus_message_read(m, "s", &iface) < 0 || !iface)
            return 0;
        const Props changes = to_props(read_value(m));
        const std::string path = sd_bus_message_get_path(m) ? sd_bus_message_get_path(m) : "";
        Props& stored = self->objects_[path][iface];
        const Props before = stored;
        for (const auto& [name, value] : changes)
            stored[name] = value;
        self->changed_(path, iface, changes, before);
    } catch (const Failure&) {
        // A malformed signal changes nothing.
    }
    return 0;
}

int ObjectMirror::on_owner_changed(sd_bus_message* m, void* userdata, sd_bus_error*) {
    auto* self = static_cast<ObjectMirror*>(userdata);
    const char *name = nullptr, *old_owner = nullptr, *new_owner = nullptr;
    if (sd_bus_message_read(m, "sss", &name, &old_owner, &new_owner) >= 0 && name &&
        std::string_view(name) == caracara::dbus::kBusName && new_owner && *new_owner)
        self->restarted_();
    return 0;
}

} // namespace caracara::client
