// One object on the bus: its vtable, made from a Member table, and PropertiesChanged for the
// members that a change announces.
#pragma once

#include "drivers/sdbus/property.hpp"
#include "drivers/sdbus/sdbus.hpp"

#include <span>
#include <string>
#include <vector>

namespace caracara::dbus {

class AnnouncedObject {
public:
    enum class When { Always, Changed };

    template <size_t N>
    AnnouncedObject(sd_bus* bus, std::string path, const char* iface, const Member (&members)[N],
                    const std::array<sd_bus_vtable, N + 2>& vtable, void* userdata)
        : bus_(bus), path_(std::move(path)), iface_(iface), members_(members), vtable_(vtable.data()),
          userdata_(userdata), published_(N) {}

    // Registers the vtable and takes the values of now as the announced ones.
    int start();
    // PropertiesChanged for the members announced by `changes`: all of them, or those whose value
    // differs from the one last announced.
    int announce(uint32_t changes, When when);

    sd_bus* bus() const { return bus_; }
    const std::string& path() const { return path_; }
    const char* iface() const { return iface_; }

private:
    bool changed(size_t i);
    int emit(uint64_t which);

    sd_bus* bus_;
    std::string path_;
    const char* iface_;
    std::span<const Member> members_;
    const sd_bus_vtable* vtable_;
    void* userdata_;
    SlotPtr slot_;
    std::vector<std::string> published_; // each member's value as last announced, encoded
    std::string scratch_;
};

} // namespace caracara::dbus
