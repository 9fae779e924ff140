#include "sim/inspector.hpp"

#include "sim/inspect_reply.hpp"
#include "sim/inspect_simulator.hpp"
#include "sim/inspect_teensy.hpp"
#include "sim/inspect_thruster.hpp"

#include <string>

namespace caracara::sim {

int Inspector::add(const std::string& path, const char* iface, const sd_bus_vtable* vtable, void* userdata) {
    sd_bus_slot* slot = nullptr;
    int r = sd_bus_add_object_vtable(bus_, &slot, path.c_str(), iface, vtable, userdata);
    if (r >= 0)
        slots_.emplace_back(slot);
    return r;
}

int Inspector::start() {
    sd_bus_slot* slot = nullptr;
    int r = sd_bus_add_object_manager(bus_, &slot, kInspectRoot);
    if (r < 0)
        return r;
    slots_.emplace_back(slot);
    const std::string root = kInspectRoot;
    if ((r = add(root, "org.caracara.Simulator1", simulator_inspection(), &parts_)) < 0)
        return r;
    auto& ts = parts_.vehicle.thrusters();
    for (size_t i = 0; i < ts.size(); ++i)
        if ((r = add(root + "/thruster/" + std::to_string(i), "org.caracara.Simulator1.Thruster", thruster_inspection(),
                     ts[i].get())) < 0)
            return r;
    if ((r = add(root + "/teensy", "org.caracara.Simulator1.Teensy", teensy_inspection(), &parts_.vehicle)) < 0)
        return r;
    return sd_bus_request_name(bus_, "org.caracara.Simulator1", 0);
}

} // namespace caracara::sim
