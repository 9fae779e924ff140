#include "drivers/sdbus/sdbus.hpp"

namespace caracara::dbus {

std::string BusChoice::describe() const {
    switch (kind) {
    case Kind::System: return "the system bus";
    case Kind::User: return "the user bus";
    case Kind::Address: return "the bus at " + address;
    case Kind::Remote: return "the system bus of " + address + " (over SSH)";
    }
    return "?";
}

int open_bus(const BusChoice& choice, const char* description, BusPtr& out) {
    sd_bus* bus = nullptr;
    int r = 0;
    switch (choice.kind) {
    case BusChoice::Kind::System:
        r = sd_bus_open_system_with_description(&bus, description);
        break;
    case BusChoice::Kind::User:
        r = sd_bus_open_user_with_description(&bus, description);
        break;
    case BusChoice::Kind::Address:
        r = sd_bus_new(&bus);
        if (r < 0)
            return r;
        sd_bus_set_description(bus, description);
        r = sd_bus_set_address(bus, choice.address.c_str());
        if (r >= 0) r = sd_bus_set_bus_client(bus, 1);
        if (r >= 0) r = sd_bus_start(bus);
        break;
    case BusChoice::Kind::Remote:
        // Forks ssh now; the login and the bridge's Hello complete on the first call.
        r = sd_bus_open_system_remote(&bus, choice.address.c_str());
        if (r >= 0)
            sd_bus_set_description(bus, description);
        break;
    }
    if (r < 0) {
        sd_bus_unref(bus);
        return r;
    }
    out.reset(bus);
    return 0;
}

} // namespace caracara::dbus
