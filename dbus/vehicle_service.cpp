#include "dbus/vehicle_service.hpp"

#include "dbus/error_reply.hpp"
#include "dbus/vehicle_names.hpp"

namespace caracara::dbus {

VehicleService::VehicleService(sd_bus* bus, const Parts& parts)
    : bus_(bus), events_(parts.events), vehicle_(bus, parts.vehicle), teensy_(bus, parts.teensy),
      i2c_bus_object_(bus, parts.monitor), clients_(bus, parts.vehicle.vehicle),
      announcer_(bus, [this](uint32_t changes) { announce(changes); }) {
    for (size_t i = 0; i < parts.thrusters.size(); ++i)
        thrusters_.push_back(std::make_unique<ThrusterObject>(bus, parts.thrusters, i));
    // The dive recorder writes who called beside each state change: the sender of the message
    // being dispatched, if any (a timer or the kill switch has none).
    events_.set_caller_source([bus] {
        sd_bus_message* m = sd_bus_get_current_message(bus);
        return m ? sender(m) : std::string();
    });
}

VehicleService::~VehicleService() {
    events_.set_caller_source(nullptr);
    if (bus_)
        sd_bus_release_name(bus_, kBusName);
}

int VehicleService::start() {
    sd_bus_slot* slot = nullptr;
    int r = sd_bus_add_object_manager(bus_, &slot, kRootPath);
    if (r < 0)
        return r;
    object_manager_.reset(slot);
    if ((r = vehicle_.start()) < 0)
        return r;
    for (auto& t : thrusters_)
        if ((r = t->start()) < 0)
            return r;
    if ((r = teensy_.start()) < 0 || (r = i2c_bus_object_.start()) < 0 || (r = clients_.start()) < 0)
        return r;
    return sd_bus_request_name(bus_, kBusName, 0);
}

void VehicleService::announce(uint32_t changes) {
    vehicle_.announce(changes);
    for (auto& t : thrusters_)
        t->announce(changes);
    teensy_.announce(changes);
    i2c_bus_object_.announce(changes);
}

} // namespace caracara::dbus
