#include "dbus/client_tracker.hpp"

namespace caracara::dbus {

// Installed synchronously before the name is requested, so a controlling client that leaves
// right after its command cannot slip past an asynchronously installed match.
int ClientTracker::start() {
    sd_bus_slot* slot = nullptr;
    int r = sd_bus_add_match(bus_, &slot,
                             "type='signal',sender='org.freedesktop.DBus',path='/org/freedesktop/DBus',"
                             "interface='org.freedesktop.DBus',member='NameOwnerChanged'",
                             on_name_owner_changed, this);
    if (r >= 0)
        slot_.reset(slot);
    return r;
}

int ClientTracker::on_name_owner_changed(sd_bus_message* m, void* userdata, sd_bus_error*) {
    const char *name = nullptr, *old_owner = nullptr, *new_owner = nullptr;
    if (sd_bus_message_read(m, "sss", &name, &old_owner, &new_owner) < 0)
        return 0;
    if (name && name[0] == ':' && new_owner && new_owner[0] == '\0')
        static_cast<ClientTracker*>(userdata)->vehicle_.client_left(name);
    return 0;
}

} // namespace caracara::dbus
